#!/usr/bin/env python3
"""check_layers.py -- the library's folders call only down (src/README.md):
every symbol an object file of a library folder uses from another folder
must come from a lower layer, and every internal header a source includes
must live in its own folder or a lower layer.  Reads the object files of
the build (nm).  Prints each upward call or include; exits 1 if any.
Usage: check_layers.py SRC_DIR OBJ_DIR"""
import os
import re
import subprocess
import sys

# rank of each library folder; a folder may use only folders of lower rank
RANK = {'core': 0, 'spatial': 1, 'robust': 1, 'io': 1, 'eval': 2, 'estimate': 3}


def main():
    src, obj = sys.argv[1], sys.argv[2]
    bad = []
    defined, used = {}, []
    for folder in RANK:
        d = os.path.join(obj, folder)
        if not os.path.isdir(d):
            continue
        for f in sorted(os.listdir(d)):
            if not f.endswith('.o'):
                continue
            out = subprocess.run(['nm', os.path.join(d, f)], capture_output=True,
                                 text=True, check=True).stdout
            for line in out.splitlines():
                parts = line.split()
                if len(parts) == 3 and parts[1] in 'TDBR':
                    defined[parts[2]] = folder
                elif len(parts) == 2 and parts[0] == 'U':
                    used.append((folder, f[:-2], parts[1]))
    for folder, f, sym in used:
        g = defined.get(sym)
        if g and g != folder and RANK[g] >= RANK[folder]:
            bad.append('%s/%s uses %s from %s/: a call up or sideways' % (folder, f, sym, g))
    # internal headers: where each lives
    home = {}
    for folder in RANK:
        for f in os.listdir(os.path.join(src, folder)):
            if f.endswith('.h'):
                home[f] = folder
    for folder in RANK:
        for f in sorted(os.listdir(os.path.join(src, folder))):
            if not f.endswith(('.c', '.h')):
                continue
            with open(os.path.join(src, folder, f), encoding='utf-8') as fh:
                for no, line in enumerate(fh, 1):
                    m = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
                    if not m:
                        continue
                    g = home.get(os.path.basename(m.group(1)))
                    if g and g != folder and RANK[g] >= RANK[folder]:
                        bad.append('src/%s/%s:%d: includes %s from %s/: an include up or sideways'
                                   % (folder, f, no, m.group(1), g))
    for b in sorted(set(bad)):
        print(b)
    print('check_layers: %d symbol uses checked, %d upward' % (len(used), len(set(bad))))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
