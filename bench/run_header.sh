# Sourced by the bench/*_run.sh scripts: the provenance of a results CSV.
#   bench_revision BUILD_DIR   the revision the build was made from
#   bench_driver               the Vulkan driver of this machine
bench_revision() {
  # Written at build time (bench/revision.cmake): right even where this
  # checkout's git metadata is stale, e.g. a copy run on another machine.
  if [ -s "$1/bench/revision.txt" ]; then
    cat "$1/bench/revision.txt"
    return
  fi
  local source_dir
  source_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  echo "$(git -C "$source_dir" rev-parse --short HEAD 2>/dev/null || echo unknown) (checkout, not the build)"
}

bench_driver() {
  local name info
  name=$(vulkaninfo --summary 2>/dev/null | awk -F'= ' '/driverName/ {print $2; exit}' || true)
  info=$(vulkaninfo --summary 2>/dev/null | awk -F'= ' '/driverInfo/ {print $2; exit}' || true)
  if [ -n "$name" ]; then
    echo "$name${info:+ $info}"
  elif command -v nvidia-smi >/dev/null 2>&1; then
    echo "NVIDIA $(nvidia-smi --query-gpu=driver_version --format=csv,noheader | head -1) (nvidia-smi)"
  else
    echo "mesa-vulkan-drivers $(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || echo unknown)"
  fi
}
