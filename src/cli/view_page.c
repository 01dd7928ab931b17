/* view_page.c -- writing the page's pieces safely: base64 for the typed
 * arrays, HTML text for titles, JSON strings for names (the page builds
 * its DOM from them with textContent, never as markup), and the inlined
 * scripts, which must not contain the "</script" that would end their
 * element (HTML 5.2 §4.12.1.3, restrictions for contents of script). */
#include <string.h>
#include <strings.h>

#include "view.h"

static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static void b64_3(FILE *f, const unsigned char *p, int m)
{
    unsigned v = (unsigned)p[0] << 16 | (unsigned)(m > 1 ? p[1] : 0) << 8 | (m > 2 ? p[2] : 0);
    char o[4] = {b64[v >> 18 & 63], b64[v >> 12 & 63], m > 1 ? b64[v >> 6 & 63] : '=',
                 m > 2 ? b64[v & 63] : '='};
    fwrite(o, 1, 4, f);
}

void jf_b64_put(jf_b64 *b, const unsigned char *p, size_t n)
{
    while (n && b->npend) {
        b->pend[b->npend++] = *p++, n--;
        if (b->npend == 3) b64_3(b->f, b->pend, 3), b->npend = 0;
    }
    for (; n >= 3; p += 3, n -= 3) b64_3(b->f, p, 3);
    while (n) b->pend[b->npend++] = *p++, n--;
}

void jf_b64_end(jf_b64 *b)
{
    if (b->npend) b64_3(b->f, b->pend, b->npend);
    b->npend = 0;
}

void jf_view_html(FILE *f, const char *s)
{
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        switch (c) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&#39;", f); break;
        default:
            if (c < 0x20 || c == 0x7f) fputs("&#xFFFD;", f);
            else fputc(c, f);
        }
    }
}

void jf_view_json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
        else if (*p < 0x20 || *p == 0x7f || *p == '<' || *p == '>' || *p == '&')
            fprintf(f, "\\u%04x", *p);
        else if (p[0] == 0xe2 && p[1] == 0x80 && (p[2] == 0xa8 || p[2] == 0xa9))
            fprintf(f, "\\u%04x", p[2] == 0xa8 ? 0x2028 : 0x2029), p += 2;
        else fputc(*p, f);
    }
    fputc('"', f);
}

void jf_view_inline_js(FILE *f, const char *js)
{
    for (const char *p = js; *p; p++) {
        if (p[0] == '<' && (!strncasecmp(p + 1, "/script", 7) || !strncmp(p + 1, "!--", 3))) {
            fputs(p[1] == '/' ? "<\\/" : "<\\!", f);
            p++;
            continue;
        }
        fputc(*p, f);
    }
}
