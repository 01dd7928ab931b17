#!/usr/bin/env python3
"""check_defaults.py -- every default of `jetfit estimate` quoted in
README.md, docs/*.md, `jetfit estimate --help`, the man page, jetfit.h's
comments and the Python module's docstring is the one the code sets
(issue 31).  The code's defaults come from print_defaults (built from
jf_cli_est_init & co.); each document is parsed where it states a default
(option tables, help blocks, man page blocks, "(default X)" in comments,
Python signatures, "`--opt X`, the default" in prose).  Prints every
disagreement; exits 1 if any.
Usage: check_defaults.py SRC PRINT_DEFAULTS JETFIT [PYTHONPATH]"""
import os
import re
import subprocess
import sys

SYN = {"1e3": "1000", "1e+03": "1000", "all": "all", "off": "off", "none": "none"}


def norm(v):
    v = v.strip().strip("`'\"").strip()
    v = re.sub(r"\s+", " ", v)
    return SYN.get(v, v)


def agree(opt, said, code):
    """said: a document's words for the default of opt; code: the value."""
    s = norm(said)
    if opt == "orient":  # the rule: scanner positions, else input normals, else none
        return ("input" in s and "none" in s and ("scanner" in s or "PTX" in s)) or \
            s.split(" ")[0] in ("auto", "JF_ORIENT_AUTO")
    if opt == "threads":
        return "all cores" in s or "all" == s
    if opt == "monge-degree":
        return s.replace(" ", "") in ("min(degree,4)", "min(max(degree,2),4)")
    if opt == "normal":  # auto: jet on a noisy cloud, else pca
        return s.startswith("auto") or ("jet" in s and "noisy" in s)
    if opt == "memory":
        return "MemAvailable" in s or "available memory" in s
    return s == code or s.split(" ")[0].rstrip(";,.") == code


def paren(text, at):
    """The text from `at` to the ')' closing the '(' before it."""
    depth, i = 1, at
    while i < len(text) and depth:
        depth += {"(": 1, ")": -1}.get(text[i], 0)
        i += 1
    return text[at:i - 1] if depth == 0 else text[at:]


def main():
    src, printer, jetfit = sys.argv[1:4]
    pypath = sys.argv[4] if len(sys.argv) > 4 else None
    code = dict(l.split("=", 1) for l in
                subprocess.run([printer], capture_output=True, text=True, check=True)
                .stdout.splitlines())
    bad, seen = [], 0

    def check(where, opt, said):
        nonlocal seen
        if opt not in code:
            return
        seen += 1
        if not agree(opt, said, code[opt]):
            bad.append("%s: --%s default '%s', the code's is '%s'" % (where, opt, said.strip(), code[opt]))

    # 1. option tables: | `--opt ARG` | default | meaning |
    for md in ["README.md"] + ["docs/" + f for f in sorted(os.listdir(os.path.join(src, "docs")))
                              if f.endswith(".md")]:
        text = open(os.path.join(src, md), encoding="utf-8").read()
        for no, line in enumerate(text.splitlines(), 1):
            m = re.match(r"\|\s*`(?:-\w, )?--([a-z-]+)[^`]*`(?:, `--[a-z-]+[^`]*`)?\s*\|\s*([^|]*)\|", line)
            if m and "| option | default |" in text and m.group(2).strip():
                check("%s:%d" % (md, no), m.group(1), m.group(2))
            # prose: "`--opt X`, the default" / "`--opt X` (the default)" / "(default `X`)"
            for m in re.finditer(r"`--([a-z-]+) ([^`]+)`,? \(?the default", line):
                check("%s:%d" % (md, no), m.group(1), m.group(2))
            for m in re.finditer(r"`--([a-z-]+)[^`]*`[^.|(]{0,30}\(default `?([^`)]+)`?\)", line):
                check("%s:%d" % (md, no), m.group(1), m.group(2))

    # 2. --help: each option's block, "default X"
    helptext = subprocess.run([jetfit, "estimate", "--help"], capture_output=True, text=True,
                              check=True).stdout
    blocks = re.split(r"\n(?=  -)", helptext)
    for b in blocks:
        m = re.match(r"\s*(?:-\w, )?--([a-z-]+)", b)
        flat = re.sub(r"\s+", " ", b)
        d = re.search(r"\(default:? ", flat)
        if m and d:
            check("estimate --help", m.group(1), paren(flat, d.end()).split(";")[0])

    # 3. the man page: .BI \-\-opt blocks up to the next .TP
    man = open(os.path.join(src, "docs/jetfit.1"), encoding="utf-8").read()
    for b in re.split(r"\n\.TP\n", man):
        if not re.match(r"\.B[IR]? \\-\\-", b):
            continue
        flat = re.sub(r"\\f[BIRP]|\\&|\\\(..", "", b).replace("\\-", "-")
        flat = re.sub(r"^\.(BR|BI|B|I|IR|RI|RB)\s", "", flat, flags=re.M).replace('"', "")
        flat = re.sub(r"\s+", " ", flat)
        # a default belongs to the last option named before it
        for d in re.finditer(r"default:? ([^;).]+)", flat):
            names = re.findall(r"--([a-z][a-z-]*)", flat[:d.start()])
            if names:
                check("jetfit.1", names[-1], d.group(1))

    # 4. jetfit.h: struct fields' "(default X)"
    field = {"degree": "degree", "fit": "fit", "frame": "frame", "max_cond": "max-cond",
             "robust": "robust", "nb": "neighbors", "orient": "orient", "normal": "normal"}
    hdr = open(os.path.join(src, "src/jetfit.h"), encoding="utf-8").read()
    for m in re.finditer(r"\n\s+[a-z_]+ (\w+);\s+/\*(.*?)\*/", hdr, re.S):
        f, com = m.group(1), re.sub(r"\s+", " ", m.group(2))
        d = re.search(r"\(?default:? ([^,;)]+)", com)
        if f in field and d:
            said = d.group(1)
            if f == "max_cond":
                said = said.split(",")[0]
            check("jetfit.h " + f, field[f], said)
    m = re.search(r"#define JF_ESTIMATE_DEFAULT_K (\d+)", hdr)
    check("jetfit.h JF_ESTIMATE_DEFAULT_K", "neighbors", "knn:" + m.group(1))

    # 5. Python: the docstring's signature and its parameter lines
    if pypath:
        out = subprocess.run([sys.executable, "-c",
                              "import jetfit; print(jetfit.estimate.__doc__)"],
                             env=dict(os.environ, PYTHONPATH=pypath), capture_output=True, text=True)
        if out.returncode == 0:
            doc = out.stdout
            sig = doc.split("\n", 1)[0]
            for kw, val in re.findall(r"(\w+)=('[^']*'|[\w.]+)", sig):
                if val != "None" and kw != "robust_normals":
                    check("python estimate signature", kw.replace("_", "-"), val)
            for kw, val in re.findall(r"\n  (\w+) : [^\n]*?default ('[^']*'|[^:\n]+)", doc):
                check("python estimate docstring", kw.replace("_", "-"), val)
        else:
            print("note: the Python module does not import here; its docstring is not checked")
    for b in bad:
        print(b)
    print("check_defaults: %d default(s) checked, %d disagreement(s)" % (seen, len(bad)))
    return 1 if bad or seen < 20 else 0


if __name__ == "__main__":
    sys.exit(main())
