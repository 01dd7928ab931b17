#!/usr/bin/env python3
"""check_abi.py -- libjetfit.so exports exactly the functions jetfit.h
declares (issue 24.3): every exported function is declared in the header,
and every declared function is exported.  Parses the header on its own
(not through the generated version script).  Usage: check_abi.py HEADER LIB"""
import re
import subprocess
import sys


def declared(header):
    with open(header, encoding='utf-8') as fh:
        text = fh.read()
    text = re.sub(r'/\*.*?\*/', '', text, flags=re.S)
    text = re.sub(r'^\s*#.*$', '', text, flags=re.M)       # macros
    text = re.sub(r'typedef[^;]*;', '', text)                 # function pointer types
    return set(re.findall(r'\b(jf_\w+)\s*\(', text))


def exported(lib):
    out = subprocess.run(['nm', '-D', '--defined-only', lib], capture_output=True,
                         text=True, check=True).stdout
    return {p[2] for p in (l.split() for l in out.splitlines()) if len(p) == 3 and p[1] in 'TWiu'}


def main():
    hdr, lib = declared(sys.argv[1]), exported(sys.argv[2])
    extra = sorted(lib - hdr)
    missing = sorted(hdr - lib)
    for s in extra:
        print('exported but not in jetfit.h: %s' % s)
    for s in missing:
        print('declared in jetfit.h but not exported: %s' % s)
    print('check_abi: %d functions declared, %d exported, %d extra, %d missing'
          % (len(hdr), len(lib), len(extra), len(missing)))
    return 1 if extra or missing else 0


if __name__ == '__main__':
    sys.exit(main())
