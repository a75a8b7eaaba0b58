#!/usr/bin/env bash
# scripts/install-deps.sh's apt-source derivation against fake apt
# configurations (no root, nothing installed): bookworm-backports must come
# from the machine's own bookworm source, whichever format it is written in.
set -euo pipefail
source "$(dirname "$0")/../../scripts/install-deps.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

# fake NAME FILE CONTENT: writes CONTENT to $tmp/NAME/etc/apt/FILE.
fake() {
  mkdir -p "$(dirname "$tmp/$1/etc/apt/$2")"
  printf '%s\n' "$3" >"$tmp/$1/etc/apt/$2"
}
check() {  # check WHAT EXPECTED ACTUAL
  if [ "$2" != "$3" ]; then
    printf 'FAIL: %s\n--- expected\n%s\n--- got\n%s\n' "$1" "$2" "$3" >&2
    failures=$((failures + 1))
  fi
}

# deb822 behind a caching proxy; a disabled stanza and a comment come first,
# a renamed-away file with another URI is not read.
fake deb822 sources.list.d/debian.sources '# The company mirror
Types: deb
URIs: http://old.example.com/debian
Suites: bookworm
Components: main
Enabled: no

Types: deb deb-src
URIs: http://apt-proxy.corp:3142/debian
Suites: bookworm bookworm-updates
Components: main contrib
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://apt-proxy.corp:3142/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg'
fake deb822 sources.list.d/other.sources.disabled 'Types: deb
URIs: http://wrong.example.com/debian
Suites: bookworm-backports
Components: main'
check "deb822 proxy source" "# Added by vkrc's scripts/install-deps.sh, from /etc/apt/sources.list.d/debian.sources
Types: deb
URIs: http://apt-proxy.corp:3142/debian
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" "$(backports_source "$tmp/deb822")"
check "deb822: backports not configured" 1 "$(backports_configured "$tmp/deb822" && echo 0 || echo 1)"

# deb822 with the key embedded in Signed-By (continuation lines kept as they are).
fake embedded sources.list.d/mirror.sources 'Types: deb
URIs: https://mirror.example.org/debian/
Suites: bookworm
Components: main
Signed-By:
 -----BEGIN PGP PUBLIC KEY BLOCK-----
 .
 mQINBGPL0BUBEADmW5NdOOHwPIJlgPu6JDcKw/NZJPR8lsD3K87ZM18gzyQZJD+w
 -----END PGP PUBLIC KEY BLOCK-----'
check "deb822 embedded key" "# Added by vkrc's scripts/install-deps.sh, from /etc/apt/sources.list.d/mirror.sources
Types: deb
URIs: https://mirror.example.org/debian/
Suites: bookworm-backports
Components: main
Signed-By: 
 -----BEGIN PGP PUBLIC KEY BLOCK-----
 .
 mQINBGPL0BUBEADmW5NdOOHwPIJlgPu6JDcKw/NZJPR8lsD3K87ZM18gzyQZJD+w
 -----END PGP PUBLIC KEY BLOCK-----" "$(backports_source "$tmp/embedded")"

# One-line format with options; a commented-out backports line does not count.
fake oneline sources.list '# deb http://deb.debian.org/debian bookworm-backports main
deb-src http://src.example.com/debian bookworm main
deb [arch=amd64 signed-by=/etc/apt/keyrings/corp.gpg] http://mirror.corp.example/debian/ bookworm main contrib # local
deb http://mirror.corp.example/debian-security bookworm-security main'
check "one-line source with signed-by" "# Added by vkrc's scripts/install-deps.sh, from /etc/apt/sources.list
Types: deb
URIs: http://mirror.corp.example/debian/
Suites: bookworm-backports
Components: main
Signed-By: /etc/apt/keyrings/corp.gpg" "$(backports_source "$tmp/oneline")"
check "one-line: backports not configured" 1 "$(backports_configured "$tmp/oneline" && echo 0 || echo 1)"

# One-line in sources.list.d without signed-by: apt's trusted keyrings, so no Signed-By.
fake plain sources.list.d/local.list 'deb http://10.0.0.5:3142/deb.debian.org/debian bookworm main'
check "one-line source without signed-by" "# Added by vkrc's scripts/install-deps.sh, from /etc/apt/sources.list.d/local.list
Types: deb
URIs: http://10.0.0.5:3142/deb.debian.org/debian
Suites: bookworm-backports
Components: main" "$(backports_source "$tmp/plain")"

# Already configured, in either format: the script adds nothing.
fake has822 sources.list.d/debian.sources 'Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-backports
Components: main'
check "deb822: backports configured" 0 "$(backports_configured "$tmp/has822" && echo 0 || echo 1)"
fake hasline sources.list 'deb [ signed-by=/k.gpg ] http://m.example/debian bookworm-backports main'
check "one-line: backports configured" 0 "$(backports_configured "$tmp/hasline" && echo 0 || echo 1)"

# No bookworm source at all (another release, or only deb-src): a clear refusal.
fake none sources.list 'deb-src http://deb.debian.org/debian bookworm main
deb http://deb.debian.org/debian trixie main'
check "no bookworm source" "1 install-deps: no enabled Debian 'bookworm' source in $tmp/none/etc/apt; add bookworm-backports yourself" \
  "$(if backports_source "$tmp/none" 2>"$tmp/err"; then echo 0; else echo "1 $(cat "$tmp/err")"; fi)"
mkdir -p "$tmp/empty"
check "no apt configuration" 1 "$(backports_source "$tmp/empty" 2>/dev/null && echo 0 || echo 1)"

[ $failures -eq 0 ] && echo "install-deps: all source derivations as expected"
exit $failures
