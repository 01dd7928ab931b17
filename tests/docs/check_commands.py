#!/usr/bin/env python3
"""check_commands.py -- the doc-test (issue 31): every command of the
```sh blocks of README.md and docs/*.md runs as written, in a temporary
folder where `jetfit` is the built command, `build/` the build tree and
`data/`, `examples/`, `tests/` the repository's (read only by convention);
```python blocks run with the built module.  A block's lines run in order
in one shell (bash, -e -o pipefail), so later lines see earlier outputs.
library.md's program lines run too: the build is installed into a
temporary prefix (cmake --install), `cc app.c $(pkg-config ...)` builds
docs/library.md's first ```c block (wrapped in main, as a reader would)
and the ```cmake block builds it in a project of its own; each program
then runs on a generated scan.ply with LD_LIBRARY_PATH naming the prefix.
Skipped, and listed: installing packages (.ci/install-deps, apt, pip),
configuring and building this tree (cmake -S/--build, run-suite, the fuzz
build), what needs a cluster (mpirun) or files the repository does not
hold (a scan of theirs, a DATA folder), python blocks importing a package
that is not installed, and the program lines when cmake --install fails
(a partial build).  Exit 1 if a command fails.
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
        (r"build-fuzz/", "needs the fuzz build")]
MADE_BY_DOCS = re.compile(r"(?:-o|--output|--truth|>)\s*(\S+)")


def blocks(src):
    files = ["README.md"] + ["docs/" + f for f in sorted(os.listdir(os.path.join(src, "docs")))
                             if f.endswith(".md")]
    for f in files:
        text = open(os.path.join(src, f), encoding="utf-8").read()
        for m in re.finditer(r"```(sh|python|cmake)\n(.*?)```", text, re.S):
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


APP_HEAD = "#include <stdio.h>\n#include <stdlib.h>\n#include <jetfit.h>\n\nint main(void)\n{\n"
APP_TAIL = ('    printf("%zu points, %s\\n", c.n, jf_strerror(s));\n'
            "    free(r);\n    jf_cloud_free(&c);\n    return s != JF_OK;\n}\n")


class Prefix:
    """The build installed into tmp/prefix, once, on demand; env for a
    program built against it (pkg-config's path, the loader's path)."""

    def __init__(self, src, build, tmp):
        self.src, self.build, self.tmp, self.state = src, build, tmp, None

    def get(self):
        if self.state is None:
            p = os.path.join(self.tmp, "prefix")
            r = subprocess.run(["cmake", "--install", self.build, "--prefix", p],
                               capture_output=True, text=True)
            pc = [os.path.join(d, f) for d, _, fs in os.walk(p) for f in fs if f == "jetfit.pc"]
            if r.returncode or not pc:
                self.state = (None, "cmake --install into a temporary prefix failed (a partial "
                                    "build?): " + (r.stderr.strip()[-200:] or "no jetfit.pc"))
            else:
                libdir = os.path.dirname(os.path.dirname(pc[0]))
                self.state = ({"PKG_CONFIG_PATH": os.path.dirname(pc[0]),
                               "LD_LIBRARY_PATH": libdir, "JF_PREFIX": p}, None)
                # the reader's program: library.md's example, in main()
                lib = open(os.path.join(self.src, "docs/library.md"), encoding="utf-8").read()
                body = re.search(r"```c\n(.*?)```", lib, re.S).group(1)
                with open(os.path.join(self.tmp, "app.c"), "w") as f:
                    f.write(APP_HEAD + "".join("    " + l + "\n" for l in body.splitlines())
                            + APP_TAIL)
                subprocess.run(["jetfit", "generate", "sphere", "--n", "3000", "-o",
                                os.path.join(self.tmp, "scan.ply")], check=True,
                               env=dict(os.environ, PATH=self.build + os.pathsep +
                                        os.environ.get("PATH", "")))
        return self.state


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
        prefix = Prefix(src, build, tmp)
        for f, line, lang, body in blocks(src):
            where = "%s:%d" % (f, line)
            if lang == "cmake":  # a project of its own around the block, built and run
                penv, why = prefix.get()
                if why:
                    skipped.append("%s: cmake block (%s)" % (where, why))
                    continue
                proj = os.path.join(tmp, "cmake-app")
                os.makedirs(proj, exist_ok=True)
                shutil.copy(os.path.join(tmp, "app.c"), proj)
                with open(os.path.join(proj, "CMakeLists.txt"), "w") as fh:
                    fh.write("cmake_minimum_required(VERSION 3.16)\nproject(app C)\n"
                             "add_executable(app app.c)\n" + body)
                cmd = ("cmake -S cmake-app -B cmake-app/b -DCMAKE_PREFIX_PATH=%s >/dev/null && "
                       "cmake --build cmake-app/b >/dev/null && cmake-app/b/app"
                       % penv["JF_PREFIX"])
                r = subprocess.run([bash, "-e", "-o", "pipefail", "-c", cmd], cwd=tmp,
                                   env=dict(env, **penv), capture_output=True, text=True,
                                   timeout=600)
                ran += 1
                print("%s %s: cmake block built and run: %s" % (
                    "ok  " if r.returncode == 0 else "FAIL", where, r.stdout.strip()[-80:]))
                if r.returncode:
                    failed.append("%s: cmake block: %s" % (where, (r.stdout + r.stderr).strip()[-400:]))
                continue
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
                print("%s %s: python block" % ("ok  " if r.returncode == 0 else "FAIL", where))
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
                keep, penv = [], {}
                for seg in cmd.split(" && "):
                    why = next((w for p, w in SKIP if re.search(p, seg)), None)
                    if not why and re.match(r"cc app\.c\b", seg.strip()):
                        # the reader's program against the installed library, then run
                        penv, why = prefix.get()
                        if not why:
                            keep.append(seg + " && ./app")
                            continue
                    ext = None if why else external_inputs(seg, src, made)
                    if why or ext:
                        skipped.append("%s: `%s` (%s)" % (where, seg.strip()[:70],
                                                            why or "needs " + ext))
                        continue
                    keep.append(seg)
                    made.update(m.group(1) for m in MADE_BY_DOCS.finditer(seg))
                if keep:
                    script.append((" && ".join(keep), penv or {}))
            for cmd, penv in script:
                args = [bash, "-e", "-o", "pipefail", "-c", cmd] if bash.endswith("bash") else \
                    ["sh", "-e", "-c", cmd]
                r = subprocess.run(args, cwd=tmp, env=dict(env, **penv), capture_output=True,
                                   text=True, timeout=900)
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
