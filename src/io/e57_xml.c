/*
 * e57_xml.c -- the XML section of an E57 file (ASTM E2807, section 8) as a
 * small tree of elements, parsed by expat (Debian's libexpat1-dev).
 *
 * design: E57's XML is a tree of typed nodes (Structure, Vector,
 * CompressedVector, Integer, ScaledInteger, Float, String, Blob): the
 * element name is the node's name, the `type` attribute its type, a leaf's
 * value its character data.  The tree is kept whole (a few KB per scan) and
 * walked by io_e57.c.  Element names keep their prefixes ("las:..."): the
 * standard's own names have none (the default namespace).
 */
#include "e57.h"

#include <expat.h>
#include <stdlib.h>
#include <string.h>

#define MAX_DEPTH 64 /* far more than E57's trees use (about 8) */

typedef struct {
    jf_e57_xml *x;
    size_t cap;
    char **str;          /* every string made, freed together */
    size_t nstr, capstr;
    int stack[MAX_DEPTH];
    int depth;
    char *text;          /* the open element's character data */
    size_t tlen, tcap;
    int failed;          /* 1 no memory, 2 too deep */
    XML_Parser p;
} builder;

/* n bytes that live until jf__e57_xml_free. */
static void *grab(builder *b, size_t n)
{
    if (b->nstr == b->capstr) {
        size_t nc = b->capstr ? 2 * b->capstr : 256;
        char **q = realloc(b->str, nc * sizeof *q);
        if (!q)
            return NULL;
        b->str = q;
        b->capstr = nc;
    }
    char *d = malloc(n);
    if (d)
        b->str[b->nstr++] = d;
    return d;
}

static char *keep(builder *b, const char *s, size_t n)
{
    char *d = grab(b, n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

static void stop(builder *b, int why)
{
    if (!b->failed)
        b->failed = why;
    XML_StopParser(b->p, XML_FALSE);
}

static void XMLCALL on_start(void *ud, const XML_Char *name, const XML_Char **atts)
{
    builder *b = ud;
    if (b->failed)
        return;
    if (b->depth == MAX_DEPTH)
        return stop(b, 2);
    jf_e57_xml *x = b->x;
    if (x->n == b->cap) {
        size_t nc = b->cap ? 2 * b->cap : 64;
        jf_e57_node *q = realloc(x->node, nc * sizeof *q);
        if (!q)
            return stop(b, 1);
        x->node = q;
        b->cap = nc;
    }
    size_t na = 0;
    while (atts[na])
        na++;
    jf_e57_node *nd = &x->node[x->n];
    memset(nd, 0, sizeof *nd);
    nd->parent = b->depth ? b->stack[b->depth - 1] : -1;
    nd->child = nd->next = -1;
    nd->line = (size_t)XML_GetCurrentLineNumber(b->p);
    nd->name = keep(b, name, strlen(name));
    nd->attr = grab(b, (na + 1) * sizeof(char *));
    if (!nd->name || !nd->attr)
        return stop(b, 1);
    for (size_t k = 0; k < na; k++)
        if (!(nd->attr[k] = keep(b, atts[k], strlen(atts[k]))))
            return stop(b, 1);
    nd->attr[na] = NULL;
    int me = (int)x->n++;
    if (nd->parent >= 0) { /* append as the parent's last child */
        int *link = &x->node[nd->parent].child;
        while (*link >= 0)
            link = &x->node[*link].next;
        *link = me;
    }
    b->stack[b->depth++] = me;
    b->tlen = 0;
}

static void XMLCALL on_end(void *ud, const XML_Char *name)
{
    builder *b = ud;
    (void)name;
    if (b->failed || !b->depth)
        return;
    jf_e57_node *nd = &b->x->node[b->stack[--b->depth]];
    const char *s = b->text ? b->text : "";
    size_t n = b->tlen;
    while (n && (unsigned char)s[0] <= ' ')
        s++, n--;
    while (n && (unsigned char)s[n - 1] <= ' ')
        n--;
    /* a parent's text is what lies between its children: blanks, dropped */
    if (!(nd->text = keep(b, s, n)))
        return stop(b, 1);
    b->tlen = 0;
}

static void XMLCALL on_text(void *ud, const XML_Char *s, int len)
{
    builder *b = ud;
    if (b->failed || len <= 0)
        return;
    if (b->tlen + (size_t)len > b->tcap) {
        size_t nc = b->tcap ? b->tcap : 256;
        while (nc < b->tlen + (size_t)len)
            nc *= 2;
        char *q = realloc(b->text, nc);
        if (!q)
            return stop(b, 1);
        b->text = q;
        b->tcap = nc;
    }
    memcpy(b->text + b->tlen, s, (size_t)len);
    b->tlen += (size_t)len;
}

/* The strings live in one array of pointers: arena = {strings, count}. */
typedef struct {
    char **str;
    size_t n;
} arena;

void jf__e57_xml_free(jf_e57_xml *x)
{
    if (!x)
        return;
    arena *a = x->arena;
    if (a) {
        for (size_t k = 0; k < a->n; k++)
            free(a->str[k]);
        free(a->str);
        free(a);
    }
    free(x->node);
    memset(x, 0, sizeof *x);
}

jf_status jf__e57_xml_parse(const char *s, size_t len, const char *name, jf_e57_xml *x,
                            jf_error *err)
{
    memset(x, 0, sizeof *x);
    builder b = {0};
    b.x = x;
    arena *a = calloc(1, sizeof *a);
    b.p = a ? XML_ParserCreate(NULL) : NULL;
    if (!b.p) {
        free(a);
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for the XML parser");
    }
    XML_SetUserData(b.p, &b);
    XML_SetElementHandler(b.p, on_start, on_end);
    XML_SetCharacterDataHandler(b.p, on_text);
    jf_status st = JF_OK;
    /* expat takes an int length: feed the section in pieces */
    size_t done = 0;
    enum XML_Status xs = XML_STATUS_OK;
    do {
        size_t piece = len - done > (1u << 30) ? (1u << 30) : len - done;
        done += piece;
        xs = XML_Parse(b.p, s + done - piece, (int)piece, done == len);
    } while (xs == XML_STATUS_OK && done < len);
    if (b.failed == 1)
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for the XML section");
    else if (b.failed == 2)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "XML line %lu: elements nested deeper "
                        "than %d", (unsigned long)XML_GetCurrentLineNumber(b.p), MAX_DEPTH);
    else if (xs != XML_STATUS_OK)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "XML section, line %lu column %lu: %s",
                        (unsigned long)XML_GetCurrentLineNumber(b.p),
                        (unsigned long)XML_GetCurrentColumnNumber(b.p) + 1,
                        XML_ErrorString(XML_GetErrorCode(b.p)));
    else if (x->n == 0)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "XML section: no element");
    XML_ParserFree(b.p);
    free(b.text);
    a->str = b.str;
    a->n = b.nstr;
    x->arena = a;
    if (st != JF_OK)
        jf__e57_xml_free(x);
    return st;
}

int jf__e57_child(const jf_e57_xml *x, int i, const char *name)
{
    if (i < 0)
        return -1;
    for (int k = x->node[i].child; k >= 0; k = x->node[k].next)
        if (!strcmp(x->node[k].name, name))
            return k;
    return -1;
}

const char *jf__e57_attr(const jf_e57_xml *x, int i, const char *name)
{
    if (i < 0)
        return NULL;
    for (const char **a = x->node[i].attr; a[0] && a[1]; a += 2)
        if (!strcmp(a[0], name))
            return a[1];
    return NULL;
}
