#!/usr/bin/env python3
"""check_commands.py -- the doc-test (issue 31): every command of the
```sh blocks of README.md and docs/*.md runs as written, in a temporary
folder where `jetfit` is the built command, `build/` the build tree and
`data/`, `examples/`, `tests/` the repository's (read only by convention);
```python blocks run with the built module.  A block's lines run in order
in one shell (bash, -e -o pipefail), so later lines see earlier outputs.
Skipped, and listed: installing (.ci/install-deps, apt, pip, cmake
--install), configuring and building (cmake -S/--build, run-suite, the
fuzz build), what needs a cluster (mpirun) or files the repository does
not hold (the reader's own C program, a scan of theirs, a DATA folder), and python blocks importing a
package that is not installed.  Exit 1 if a command fails.
Usage: check_commands.py SRC BUILD"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

SKIP = [(r"\.ci/install-deps|\bapt(-get)?\b|\bsudo\b", "installs packages"),
        (r"\bpip3? install\b|cmake --install", "installs"),
        (r"cmake -S|cmake --build|tests/run-suite", "configures or builds (the suite's own job)"),
        (r"\bmpirun\b", "needs MPI ranks and a hostfile"),
        (r"^cc \w+[.]c\b", "needs the reader's own C program"),
        (r"build-fuzz/", "needs the fuzz build")]
MADE_BY_DOCS = re.compile(r"(?:-o|--output|--truth|>)\s*(\S+)")


def blocks(src):
    files = ["README.md"] + ["docs/" + f for f in sorted(os.listdir(os.path.join(src, "docs")))
                             if f.endswith(".md")]
    for f in files:
        text = open(os.path.join(src, f), encoding="utf-8").read()
        for m in re.finditer(r"```(sh|python)\n(.*?)```", text, re.S):
            yield f, text[:m.start()].count("\n") + 1, m.group(1), m.group(2)


def external_inputs(cmd, src, made):
    """Input files the command names that neither the repository nor an
    earlier command makes."""
    for tok in re.findall(r"[\w./-]+\.(?:ply|las|laz|xyz|pts|csv|txt|off|ptx|e57)\b", cmd):
        if tok in made or os.path.exists(os.path.join(src, tok)):
            continue
        # an output of this very command is not an input
        if re.search(r"(?:-o|--output|--truth)\s*" + re.escape(tok), cmd):
            continue
        return tok
    return None


def main():
    src, build = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    bash = shutil.which("bash") or "sh"
    ran, skipped, failed = 0, [], []
    env = dict(os.environ, PATH=build + os.pathsep + os.environ.get("PATH", ""),
               PYTHONPATH=os.path.join(build, "python"))
    with tempfile.TemporaryDirectory(prefix="jf-doctest.") as tmp:
        for d in ("data", "examples", "tests"):
            os.symlink(os.path.join(src, d), os.path.join(tmp, d))
        os.symlink(build, os.path.join(tmp, "build"))
        for f, line, lang, body in blocks(src):
            where = "%s:%d" % (f, line)
            if lang == "python":
                mods = re.findall(r"^import ([\w., ]+)", body, re.M)
                missing = [m.strip().split(" as ")[0] for ms in mods for m in ms.split(",")
                           if subprocess.run([sys.executable, "-c", "import " + m.strip().split(" as ")[0]],
                                             env=env, capture_output=True).returncode]
                if missing:
                    skipped.append("%s: python (no %s)" % (where, ", ".join(missing)))
                    continue
                if re.search(r"read_point_cloud\(\"scan\.ply\"\)", body):
                    skipped.append("%s: python (needs scan.ply)" % where)
                    continue
                r = subprocess.run([sys.executable, "-c", body], cwd=tmp, env=env,
                                   capture_output=True, text=True, timeout=600)
                ran += 1
                if r.returncode:
                    failed.append("%s: python block: %s" % (where, r.stderr.strip()[-400:]))
                continue
            lines = re.sub(r"\\\n", " ", body).splitlines()
            made = set()
            script = []
            for cmd in lines:
                cmd = cmd.split("  #")[0].strip()
                if not cmd or cmd.startswith("#"):
                    continue
                keep = []
                for seg in cmd.split(" && "):
                    why = next((w for p, w in SKIP if re.search(p, seg)), None)
                    ext = None if why else external_inputs(seg, src, made)
                    if why or ext:
                        skipped.append("%s: `%s` (%s)" % (where, seg.strip()[:70],
                                                            why or "needs " + ext))
                        continue
                    keep.append(seg)
                    made.update(m.group(1) for m in MADE_BY_DOCS.finditer(seg))
                if keep:
                    script.append(" && ".join(keep))
            for cmd in script:
                args = [bash, "-e", "-o", "pipefail", "-c", cmd] if bash.endswith("bash") else \
                    ["sh", "-e", "-c", cmd]
                r = subprocess.run(args, cwd=tmp, env=env, capture_output=True, text=True,
                                   timeout=900)
                ran += 1
                print("%s %s: %s" % ("ok  " if r.returncode == 0 else "FAIL", where, cmd[:100]))
                if r.returncode:
                    failed.append("%s: `%s` exit %d: %s" % (where, cmd, r.returncode,
                                                            r.stderr.strip()[-400:]))
    for s in skipped:
        print("skipped %s" % s)
    for x in failed:
        print("FAIL " + x)
    print("check_commands: %d run, %d skipped, %d failed" % (ran, len(skipped), len(failed)))
    return 1 if failed or ran == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
