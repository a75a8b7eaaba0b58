#!/usr/bin/env bash
# Regenerates the documentation's diagrams from their text sources:
# docs/object_graph.dot -> docs/object_graph.svg. Needs Graphviz (Debian:
# graphviz), a documentation-time tool only: neither the build nor the tests
# use it, so scripts/install-deps.sh does not install it.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v dot >/dev/null; then
    echo "gen_docs_diagrams: Graphviz's dot is missing (apt-get install graphviz)" >&2
    exit 1
fi
for source in docs/*.dot; do
    dot -Tsvg "$source" -o "${source%.dot}.svg"
    echo "wrote ${source%.dot}.svg"
done
