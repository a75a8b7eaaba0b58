#!/usr/bin/env bash
# Runs a command with DISPLAY set to a private Xvfb on the first free display
# number in :90..:150, and stops the server afterwards. Usage: with_xvfb.sh CMD...
set -euo pipefail
for n in $(seq 90 150); do
    [ -e "/tmp/.X$n-lock" ] || [ -e "/tmp/.X11-unix/X$n" ] && continue
    Xvfb ":$n" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
    pid=$!
    # Ours once its lock file names it and its socket exists; if another
    # server won the number, ours exits and the next number is tried.
    for _ in $(seq 500); do
        kill -0 "$pid" 2>/dev/null || break
        if [ "$(tr -d ' ' < "/tmp/.X$n-lock" 2>/dev/null)" = "$pid" ] && [ -e "/tmp/.X11-unix/X$n" ]; then
            trap 'kill "$pid"; wait "$pid" 2>/dev/null || true' EXIT
            DISPLAY=":$n" "$@"
            exit $?
        fi
        sleep 0.01
    done
    kill "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
done
echo "with_xvfb.sh: no free display number in :90..:150" >&2
exit 1
