#!/usr/bin/env python3
"""check_options.py -- every command's options come from one place (issue
31): the option tables its command line is scanned with (the
`jf_cli_optdef` rows of src/cli/*.c and src/cmdline/*.c, args.h).  For each command of
src/cli/main.c and for jetfit-mpi:
  1. its `--help` names every option of its tables (an alias may be left
     out; estimate's options may be covered by a stated reference, such as
     study's "any other estimate option") and names no option they lack;
     a short letter is shown as "-x, --long";
  2. its block of the man page (docs/jetfit.1) does the same;
  3. where --help and the man page both state an option's default, they
     state the same one;
  4. docs/cli.md's estimate table lists exactly estimate's options; the
     other commands' lines there, README.md's option table and
     docs/study.md's table name no option the command lacks.
(Estimate's defaults against the code: check_defaults.py.)
Prints every disagreement; exits 1 if any.  With --plant, first plants
three discrepancies (an option dropped from generate's help, an unknown
one in the man page's render block, a table row nothing documents) and
exits 0 only if exactly those three are reported: the check can fail.
Usage: check_options.py SRC JETFIT [JETFIT_MPI] [--plant]"""
import os
import re
import subprocess
import sys

# Each command: the file whose `tables[] = {...}` lists its tables.
SOURCES = {"estimate": "src/cmdline/opts.c", "generate": "src/cli/cmd_generate.c",
           "convergence": "src/cli/cmd_convergence.c", "render": "src/cli/cmd_render.c",
           "eval": "src/cli/cmd_eval.c", "study": "src/cli/study_args.c",
           "view": "src/cli/cmd_view.c", "jetfit-mpi": "src/cmdline/opts.c"}
# Documents that cover estimate's options by reference: (command, the
# words that must be there).
BY_REFERENCE = {"study": "estimate option", "view": "jetfit estimate --help",
                "jetfit-mpi": "jetfit estimate --help"}
MAN_REFERENCE = {"study": "estimate option", "view": "estimate's options",
                 "jetfit-mpi": "the same options"}
# Options a command takes outside its tables (main's own).
EXTRA = {"jetfit-mpi": {"--version"}}
ROW = re.compile(r'\{"(--[a-z][a-z0-9-]*)",\s*([01]),\s*(0|\'.\'),\s*(NULL|"--[a-z0-9-]+")\}')
OPT = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def tables_of(src):
    """{command: {long name: (short or None, alias_of or None)}} and the
    estimate options' table (the one every estimating command shares)."""
    defs = {}  # (file, table name) -> rows
    files = [os.path.join(d, f) for d in ("src/cli", "src/cmdline")
             for f in os.listdir(os.path.join(src, d)) if f.endswith(".c")]
    for f in files:
        text = open(os.path.join(src, f), encoding="utf-8").read()
        for m in re.finditer(r"jf_cli_optdef (\w+)\[\] = \{(.*?)\};", text, re.S):
            rows = {}
            for r in ROW.finditer(m.group(2)):
                rows[r.group(1)] = (r.group(3)[1] if r.group(3) != "0" else None,
                                    None if r.group(4) == "NULL" else r.group(4).strip('"'))
            defs[(f, m.group(1))] = rows
    est = defs[("src/cmdline/opts.c", "jf_cli_est_optdefs")]
    out = {}
    for cmd, f in SOURCES.items():
        text = open(os.path.join(src, f), encoding="utf-8").read()
        names = set()
        for m in re.finditer(r"tables\[\] = \{([^}]*)\}", text):
            names.update(n.strip() for n in m.group(1).split(",") if n.strip() != "NULL")
        rows = {}
        for n in sorted(names):
            t = defs.get((f, n)) or next((v for (ff, nn), v in defs.items() if nn == n), None)
            if t is None:
                raise SystemExit("check_options: %s: table %s not found" % (f, n))
            rows.update(t)
        out[cmd] = rows
    return out, est


def flat_man(text):
    text = re.sub(r"\\f[BIRP]|\\&|\\\(..", "", text).replace("\\-", "-")
    text = re.sub(r"^\.(BR|BI|B|I|IR|RI|RB|TP|RS|RE|PP|br)\b ?", "", text, flags=re.M)
    return text.replace('"', "")


def man_blocks(man):
    """{command: its text in the man page}."""
    sec = man[man.index(".SH COMMANDS"):]
    end = sec.index("\n.SH ", 5)
    cmds = sec[:end]
    out = {}
    parts = re.split(r"^\.TP\n\.B (estimate|generate|convergence|render|eval|study|view)\n",
                     cmds, flags=re.M)
    for i in range(1, len(parts), 2):
        body = parts[i + 1]
        body = body.split("\n.SS ")[0]
        out[parts[i]] = flat_man(body)
    m = re.search(r"\.SS Distributed runs\n(.*?)(?=\n\.S[HS] )", man, re.S)
    if m:
        out["jetfit-mpi"] = flat_man(m.group(1))
    return out


def defaults(text):
    """{--opt: the first word of its default} from an option list: each
    option block starts at a line's first option."""
    out = {}
    for b in re.split(r"\n(?=\s*(?:-\w, )?--[a-z])", text):
        m = re.match(r"\s*(?:-\w, )?(--[a-z][a-z0-9-]*)", b)
        flat = re.sub(r"\s+", " ", b)
        d = re.search(r"\(default:? ([^;,:)\s]+)", flat)
        if m and d and len(OPT.findall(flat[:d.start()])) == 1:
            out[m.group(1)] = d.group(1).strip("`'.")
    return out


def check_doc(where, text, rows, est, ref_words, extra, complete, bad, shorts=False):
    """Rule 1/2 for one document of one command.  est: the options a
    reference (ref_words in the text) covers."""
    named = set(OPT.findall(text))
    known = set(rows) | extra
    for o in sorted(named - known):
        # a unique prefix is an option too (how the command reads it)
        if len({a or k for k, (s, a) in rows.items() if k.startswith(o)}) == 1 and len(o) > 3:
            continue
        bad.append("%s: names %s, which the command's option table lacks" % (where, o))
    if not complete:
        return
    by_ref = ref_words is not None and ref_words in text
    for o, (short, alias) in sorted(rows.items()):
        if alias or o in named or (by_ref and o in est):
            continue
        bad.append("%s: does not name %s (an option of the command's table)" % (where, o))
    if shorts:
        for o, (short, alias) in sorted(rows.items()):
            if short and not alias and not re.search(r"-%s, %s\b" % (short, o), text) and \
                    not (by_ref and o in est):
                bad.append("%s: does not show -%s, %s" % (where, short, o))
        for s, o in re.findall(r"(?<![\w-])-(\w), (--[a-z][a-z0-9-]*)", text):
            if rows.get(o, (None,))[0] != s:
                bad.append("%s: shows -%s, %s; the table says otherwise" % (where, s, o))


def run(src, helps, man, tables, est, docs):
    bad = []
    mb = man_blocks(man)
    for cmd, rows in tables.items():
        extra = EXTRA.get(cmd, set())
        # jetfit-mpi refers to the whole of estimate's help; study and
        # view to its estimation options
        ref = set(tables["estimate"]) if cmd == "jetfit-mpi" else est
        if cmd in helps:
            check_doc(cmd + " --help", helps[cmd], rows, ref, BY_REFERENCE.get(cmd), extra,
                      True, bad, shorts=True)
        if cmd not in mb:
            bad.append("jetfit.1: no block for %s" % cmd)
            continue
        check_doc("jetfit.1 (%s)" % cmd, mb[cmd], rows, ref, MAN_REFERENCE.get(cmd), extra,
                  True, bad)
        if cmd in helps:  # rule 3
            hd, md = defaults(helps[cmd]), defaults(re.sub(r"\n\.TP\n", "\n", mb[cmd]))
            for o in sorted(set(hd) & set(md)):
                if hd[o] != md[o]:
                    bad.append("%s: default of %s: --help says '%s', jetfit.1 '%s'"
                               % (cmd, o, hd[o], md[o]))
    # rule 4
    cli = docs["docs/cli.md"]
    est_rows = [l for l in cli.split("## jetfit estimate", 1)[1].split("\n## ", 1)[0].splitlines()
                if l.startswith("| `")]
    check_doc("docs/cli.md (estimate's table)", "\n".join(est_rows), tables["estimate"], est,
              None, set(), True, bad)
    for l in cli.splitlines():
        m = re.match(r"\| `jetfit (\w+) ", l)
        if m and m.group(1) in tables:
            check_doc("docs/cli.md (%s)" % m.group(1), l.split("|")[1], tables[m.group(1)], est,
                      None, set(), False, bad)
    readme = [l for l in docs["README.md"].splitlines() if re.match(r"\| `(-\w, )?--", l)]
    check_doc("README.md (option table)", "\n".join(l.split("|")[1] for l in readme),
              tables["estimate"], est, None, set(), False, bad)
    study = [l for l in docs["docs/study.md"].splitlines() if re.match(r"\| `--", l)]
    check_doc("docs/study.md (option table)", "\n".join(l.split("|")[1] for l in study),
              tables["study"], est, None, set(), False, bad)
    return bad


def main():
    args = [a for a in sys.argv[1:] if a != "--plant"]
    plant = "--plant" in sys.argv
    src, jetfit = args[0], args[1]
    mpi = args[2] if len(args) > 2 else None
    tables, est = tables_of(src)
    main_c = open(os.path.join(src, "src/cli/main.c"), encoding="utf-8").read()
    for c in re.findall(r'\{"(\w+)", jf_cmd_\w+,', main_c):
        if c not in SOURCES:
            print("check_options: command %s has no entry in SOURCES" % c)
            return 1
    helps = {}
    for cmd in tables:
        exe = [mpi] if cmd == "jetfit-mpi" else [jetfit, cmd]
        if exe[0] is None or not os.access(exe[0], os.X_OK):
            print("note: %s is not built: its --help is not checked" % cmd)
            continue
        helps[cmd] = subprocess.run(exe + ["--help"], capture_output=True, text=True,
                                    check=True).stdout
    man = open(os.path.join(src, "docs/jetfit.1"), encoding="utf-8").read()
    docs = {f: open(os.path.join(src, f), encoding="utf-8").read()
            for f in ("README.md", "docs/cli.md", "docs/study.md")}
    if plant:
        helps["generate"] = helps["generate"].replace("--grid-h", "")
        man = man.replace("A PNG of a result coloured", "A PNG (\\-\\-planted\\-opt) of a result coloured")
        tables["eval"]["--planted-row"] = (None, None)
    bad = run(src, helps, man, tables, est, docs)
    for b in bad:
        print(b)
    n = sum(len([o for o, (s, a) in t.items() if not a]) for t in tables.values())
    print("check_options: %d commands, %d options, %d disagreement(s)" % (len(tables), n, len(bad)))
    if plant:
        want = ["generate --help: does not name --grid-h",
                "jetfit.1 (render): names --planted-opt",
                "eval --help: does not name --planted-row",
                "jetfit.1 (eval): does not name --planted-row"]
        found = [w for w in want if any(b.startswith(w) for b in bad)]
        print("planted: %d of %d reports found, %d other report(s)"
              % (len(found), len(want), len(bad) - len(found)))
        return 0 if len(found) == len(want) == len(bad) else 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
