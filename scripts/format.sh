#!/usr/bin/env bash
# Formats the C++ sources with the repository's .clang-format (Debian's
# clang-format, installed by scripts/install-deps.sh), or with --check fails
# on the first file that is not formatted (scripts/test.sh runs that).
# Usage: scripts/format.sh [--check]
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h')
if [ "${1:-}" = "--check" ]; then
    clang-format --dry-run --Werror "${files[@]}"
    echo "format: ${#files[@]} files formatted"
else
    clang-format -i "${files[@]}"
fi
