#!/usr/bin/env bash
# Installs the Debian 12 packages vkrc needs, only those that are missing.
# Uses sudo when not root. Safe to run repeatedly: a no-op when all are present.
# mesa-vulkan-drivers alone comes from bookworm-backports (Mesa 25: lavapipe
# with descriptor indexing, buffer device address and Vulkan 1.4), so the
# bindless and device-address tests run; everything stays feature-gated and
# passes on bookworm's Mesa 22.3 too. When no bookworm-backports source is
# configured, one is added from the machine's own bookworm source (its URIs
# and signing key, so a mirror or proxy keeps being used); nothing else in
# the apt configuration is touched.
# The functions take the root of the apt configuration ("" for the machine),
# so tests/scripts/install_deps_test.sh runs them against fake ones.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libvulkan-dev libvulkan1 mesa-vulkan-drivers vulkan-validationlayers
  glslang-tools libglfw3-dev libglm-dev googletest libgtest-dev xvfb libstb-dev
  clang clang-format valgrind python3 gfxreconstruct
)

backports_file=etc/apt/sources.list.d/vkrc-bookworm-backports.sources

# The enabled apt entries under ROOT, one per line, tab-separated:
# file, types, URIs, suites, components, Signed-By (its continuation lines
# joined by \037, as an embedded key has them). Both formats: one-line
# sources.list and *.list, deb822 *.sources (disabled stanzas skipped).
apt_entries() {
  local root=$1 files=()
  [ -f "$root/etc/apt/sources.list" ] && files+=("$root/etc/apt/sources.list")
  local f
  for f in "$root"/etc/apt/sources.list.d/*.list "$root"/etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && files+=("$f")
  done
  [ ${#files[@]} -eq 0 ] && return 0
  awk -v OFS='\t' '
    function reset() { split("", v); key = ""; enabled = 1 }
    function flush() {
      if ("types" in v && enabled) print file, v["types"], v["uris"], v["suites"], v["components"], v["signed-by"]
      reset()
    }
    FNR == 1 { if (deb822) flush(); file = FILENAME; deb822 = file ~ /\.sources$/; reset() }
    deb822 && /^[ \t]*#/ { next }
    deb822 && /^[ \t]*$/ { flush(); next }
    deb822 && /^[ \t]/ { if (key != "") v[key] = v[key] "\037" $0; next }
    deb822 {
      key = tolower(substr($0, 1, index($0, ":") - 1)); val = substr($0, index($0, ":") + 1)
      gsub(/^[ \t]+|[ \t]+$/, "", val); v[key] = val
      if (key == "enabled" && tolower(val) == "no") enabled = 0
      next
    }
    { sub(/#.*/, "") }
    $1 == "deb" || $1 == "deb-src" {
      type = $1; opts = ""; i = 2
      if ($2 ~ /^\[/) {
        while (i <= NF) { opts = opts " " $i; if ($i ~ /\]$/) { i++; break } i++ }
      }
      signed = ""
      if (match(opts, /signed-by=[^] ]+/)) signed = substr(opts, RSTART + 10, RLENGTH - 10)
      comps = ""; for (j = i + 2; j <= NF; j++) comps = comps (comps == "" ? "" : " ") $j
      print file, type, $i, $(i + 1), comps, signed
    }
    END { if (deb822) flush() }
  ' "${files[@]}"
}

# Whether an enabled entry under ROOT has the suite bookworm-backports.
backports_configured() {
  apt_entries "$1" | awk -F'\t' '{ n = split($4, s, " "); for (i = 1; i <= n; i++) if (s[i] == "bookworm-backports") found = 1 }
                                  END { exit !found }'
}

# The deb822 stanza for bookworm-backports, from the first enabled "deb"
# entry under ROOT with the suite bookworm: the same URIs and Signed-By.
# Fails, printing why, when there is none.
backports_source() {
  local stanza
  stanza=$(apt_entries "$1" | awk -F'\t' -v root="$1" '
    { nt = split($2, t, " "); deb = 0; for (i = 1; i <= nt; i++) if (t[i] == "deb") deb = 1
      ns = split($4, s, " "); for (i = 1; i <= ns; i++) if (deb && s[i] == "bookworm") {
        print "# Added by vkrc'"'"'s scripts/install-deps.sh, from " substr($1, length(root) + 1)
        print "Types: deb\nURIs: " $3 "\nSuites: bookworm-backports\nComponents: main"
        if ($6 != "") { gsub(/\037/, "\n", $6); print "Signed-By: " $6 }
        exit
      } }')
  if [ -z "$stanza" ]; then
    echo "install-deps: no enabled Debian 'bookworm' source in $1/etc/apt; add bookworm-backports yourself" >&2
    return 1
  fi
  printf '%s\n' "$stanza"
}

installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

main() {
  local missing=() p
  for p in "${packages[@]}"; do
    installed "$p" || missing+=("$p")
  done
  local need_backports=1
  case "$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)" in
    *bpo12*) need_backports=0 ;;
  esac
  if [ ${#missing[@]} -eq 0 ] && [ $need_backports -eq 0 ]; then
    return 0
  fi

  local sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  if [ $need_backports -eq 1 ] && ! backports_configured ""; then
    local stanza
    stanza=$(backports_source "")
    echo "install-deps: adding /$backports_file:" >&2
    printf '%s\n' "$stanza" | sed 's/^/  /' >&2
    printf '%s\n' "$stanza" | "${sudo_cmd[@]}" tee "/$backports_file" >/dev/null
  fi
  echo "install-deps: apt-get update" >&2
  "${sudo_cmd[@]}" apt-get update -q
  if [ ${#missing[@]} -gt 0 ]; then
    echo "install-deps: installing ${missing[*]}" >&2
    "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
  fi
  if [ $need_backports -eq 1 ]; then
    echo "install-deps: mesa-vulkan-drivers from bookworm-backports" >&2
    "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends -t bookworm-backports mesa-vulkan-drivers
  fi
}

# Sourced (by the test) it only defines the functions.
if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  main "$@"
fi
