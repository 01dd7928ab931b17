#!/usr/bin/env python3
"""check_refs.py -- every file or section that a comment or a document names
must exist in the repository (issue 24.4): paths such as src/io/io_las.c or
tests/run-suite, bare source names such as pipeline.c, and Markdown links
[text](docs/x.md#section).  Prints one line per dangling reference and
exits 1 if there is any.  Usage: check_refs.py [REPO_ROOT]"""
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(__file__), '..', '..'))
SCAN_DIRS = ['src', 'cgal_bridge', 'tests', 'docs', 'python', 'examples', 'cmake', '.ci']
SCAN_FILES = ['README.md', 'CMakeLists.txt']
SCAN_EXT = ('.c', '.h', '.cpp', '.hpp', '.md', '.py', '.pyi', '.sh', '.cmake', '.txt', '.1', '.in', '.js', '.html')
SKIP_DIRS = {'corpus', '__pycache__', 'node_modules'}
# generated at build time or outside the tree by design
GENERATED = {'jetfit.pc', 'jetfitConfig.cmake', 'config.h', 'node_modules',
             'app.c'}  # library.md's reader's program (the doc-test writes it)
TOPS = ('src', 'tests', 'docs', 'cgal_bridge', 'python', 'data', 'examples', 'cmake', '.ci')


DIRS_EXTRA = set()  # folders whose files are data, not scanned


def repo_files():
    out = []
    for dp, dn, fn in os.walk(ROOT):
        rel = os.path.relpath(dp, ROOT)
        parts = rel.split(os.sep)
        if parts[0].startswith('build') or parts[0] == '.git' or parts[0] == 'tmp':
            dn[:] = []
            continue
        if any(p in SKIP_DIRS for p in parts):
            DIRS_EXTRA.add(rel)
            continue
        for f in fn:
            out.append(os.path.normpath(os.path.join(rel, f)))
    return out


FILES = repo_files()
FILESET = set(FILES)
BASENAMES = {os.path.basename(f) for f in FILES}
# system and library headers (<math.h>, <check.h>, CGAL's ...) are not ours
SYSTEM = set()
for top in ('/usr/include', '/usr/lib/gcc', '/usr/lib/llvm-14/lib/clang'):
    for dp, dn, fn in os.walk(top):
        SYSTEM.update(fn)
DIRS = set(DIRS_EXTRA)
for f in FILES:
    d = os.path.dirname(f)
    while d:
        DIRS.add(d)
        d = os.path.dirname(d)

PATH_RE = re.compile(r'(?<![\w./$-])((?:%s)/[\w./-]*[\w])' % '|'.join(re.escape(t) for t in TOPS))
BARE_RE = re.compile(r'(?<![\w./*$-])([A-Za-z_][\w-]*\.(?:c|h|cpp|hpp|md))\b(?![\w/-])')
LINK_RE = re.compile(r'\]\(([^)\s]+)\)')
# a document and a quoted section of it: docs/design.md "CGAL 5.5.1"
SECTION_RE = re.compile(r'([\w./-]+\.md|README)(?:\)|\]\([^)]*\))?,? "([^"]+)"')


def anchors(path):
    """GitHub-style anchors of a Markdown file's headings."""
    out = set()
    try:
        with open(os.path.join(ROOT, path), encoding='utf-8') as fh:
            for line in fh:
                m = re.match(r'#+\s+(.*)', line)
                if m:
                    a = m.group(1).strip().lower()
                    a = re.sub(r'[^\w\- ]', '', a).replace(' ', '-')
                    out.add(a)
    except OSError:
        pass
    return out


def headings(path):
    """The lower-cased heading texts of a Markdown file."""
    out = []
    try:
        with open(os.path.join(ROOT, path), encoding='utf-8') as fh:
            out = [m.group(1).strip().lower() for m in
                   (re.match(r'#+\s+(.*)', line) for line in fh) if m]
    except OSError:
        pass
    return out


def exists(p):
    p = os.path.normpath(p.rstrip('.'))
    return p in FILESET or p in DIRS or os.path.basename(p) in GENERATED


def check_file(rel, bad):
    try:
        with open(os.path.join(ROOT, rel), encoding='utf-8') as fh:
            lines = fh.readlines()
    except (OSError, UnicodeDecodeError):
        return
    here = os.path.dirname(rel)
    fenced = False
    for no, line in enumerate(lines, 1):
        if rel.endswith('.md') and line.lstrip().startswith('```'):
            fenced = not fenced
            continue
        if line.lstrip().startswith('#include <'):
            continue
        for m in PATH_RE.finditer(line):
            p = m.group(1)
            if '*' in p or '<' in p or p.endswith(('/', '_')):
                continue
            if not exists(p):
                bad.append('%s:%d: names %s, which is not in the repository' % (rel, no, p))
        for m in SECTION_RE.finditer(line):
            doc = m.group(1) if m.group(1) != 'README' else 'README.md'
            cand = [f for f in FILES if f == doc or f.endswith(os.sep + doc)]
            for title in re.findall(r'"([^"]+)"', line[m.start():]):
                for f in cand:
                    if not any(h.startswith(title.lower()) for h in headings(f)):
                        bad.append('%s:%d: names section "%s" of %s, which it does not have'
                                   % (rel, no, title, f))
                break
        for m in BARE_RE.finditer(line):
            if fenced:
                continue
            b = m.group(1)
            stem = b.rsplit('.', 1)[0]
            if len(stem) < 3 or b in SYSTEM or line[:m.start()].endswith(('->', '.')):
                continue
            if b not in BASENAMES and b not in GENERATED:
                bad.append('%s:%d: names %s, which is not in the repository' % (rel, no, b))
        if rel.endswith('.md'):
            for m in LINK_RE.finditer(line):
                target = m.group(1)
                if re.match(r'[a-z]+:', target):
                    continue
                path, _, anchor = target.partition('#')
                full = os.path.normpath(os.path.join(here, path)) if path else rel
                if path and not exists(full):
                    bad.append('%s:%d: links to %s, which is not in the repository' % (rel, no, path))
                elif anchor and full.endswith('.md') and anchor not in anchors(full):
                    bad.append('%s:%d: links to section #%s, which %s does not have' % (rel, no, anchor, full))


def main():
    bad = []
    targets = [f for f in FILES if f.split(os.sep)[0] in SCAN_DIRS and f.endswith(SCAN_EXT)]
    targets += [f for f in SCAN_FILES if f in FILESET]
    for rel in sorted(targets):
        if ('/data/' in '/' + rel and not rel.endswith('.md')) or rel.endswith('SOURCE.md') \
           or rel == os.path.join('tests', 'docs', 'check_refs.py'):
            continue
        check_file(rel, bad)
    for b in bad:
        print(b)
    print('check_refs: %d file(s) scanned, %d dangling reference(s)' % (len(targets), len(bad)))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
