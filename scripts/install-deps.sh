#!/usr/bin/env bash
# Installs the Debian 12 packages vkrc needs, only those that are missing.
# Uses sudo when not root. Safe to run repeatedly: a no-op when all are present.
# mesa-vulkan-drivers alone comes from Debian's official bookworm-backports
# (Mesa 25: lavapipe with descriptor indexing, buffer device address and
# Vulkan 1.4), so the bindless and device-address tests run; everything stays
# feature-gated and passes on bookworm's Mesa 22.3 too.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libvulkan-dev libvulkan1 mesa-vulkan-drivers vulkan-validationlayers
  glslang-tools libglfw3-dev libglm-dev googletest libgtest-dev xvfb libstb-dev
  clang clang-format valgrind python3 gfxreconstruct
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

mesa_version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
need_backports=0
case "$mesa_version" in
  *bpo12*) ;;
  *) need_backports=1 ;;
esac

if [ ${#missing[@]} -eq 0 ] && [ $need_backports -eq 0 ]; then
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
backports=/etc/apt/sources.list.d/vkrc-bookworm-backports.sources
if [ $need_backports -eq 1 ] && ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d; then
  printf '%s\n' "Types: deb" "URIs: http://deb.debian.org/debian" "Suites: bookworm-backports" \
    "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" |
    "${sudo_cmd[@]}" tee "$backports" >/dev/null
fi
"${sudo_cmd[@]}" apt-get update -q
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}" >&2
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
if [ $need_backports -eq 1 ]; then
  echo "install-deps: mesa-vulkan-drivers from bookworm-backports" >&2
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends -t bookworm-backports mesa-vulkan-drivers
fi
