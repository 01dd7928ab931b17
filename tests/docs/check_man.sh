#!/bin/sh
# check_man.sh -- the man page renders with no troff warning (issue 31: a
# line starting with ".csv," lost a paragraph).  Usage: check_man.sh PAGE
command -v groff >/dev/null 2>&1 || { echo "SKIP: groff is not installed (Debian package groff-base)"; exit 77; }
out=$(groff -man -ww -z "$1" 2>&1)
[ -z "$out" ] || { echo "$out"; echo "check_man: $1 renders with warnings"; exit 1; }
echo "check_man: $1 renders with no warning"
