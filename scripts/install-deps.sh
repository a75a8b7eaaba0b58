#!/usr/bin/env bash
# Installs the Debian 12 packages vkrc needs, only those that are missing.
# Uses sudo when not root. Safe to run repeatedly: a no-op when all are present.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libvulkan-dev libvulkan1 mesa-vulkan-drivers vulkan-validationlayers
  glslang-tools libglfw3-dev libglm-dev googletest libgtest-dev xvfb libstb-dev
  clang clang-format valgrind python3
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
