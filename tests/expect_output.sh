#!/usr/bin/env bash
# Runs a command and passes only when it exits with 0 AND its output (stdout
# and stderr) matches an extended regular expression: ctest's
# PASS_REGULAR_EXPRESSION alone ignores the exit status, so a smoke run that
# printed its line and then failed would pass. Usage: expect_output.sh REGEX CMD...
set -uo pipefail
pattern=$1
shift
output=$("$@" 2>&1)
status=$?
printf '%s\n' "$output"
if [ "$status" -ne 0 ]; then
    echo "expect_output.sh: $1 exited with status $status" >&2
    exit 1
fi
if ! grep -Eq -- "$pattern" <<<"$output"; then
    echo "expect_output.sh: the output of $1 does not match /$pattern/" >&2
    exit 1
fi
