# Sourced by the bench/*_run.sh scripts: the provenance of a results CSV.
#   bench_start BUILD_DIR OUT  makes OUT, a runtime directory for lavapipe, and
#                              sets revision, driver and date_utc for the run
#   bench_revision BUILD_DIR   the revision the build was made from
#   bench_driver               the Vulkan driver of this machine
bench_start() {
  mkdir -p "$2"
  export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d /tmp/vkrc-xdg.XXXXXX)}"
  revision=$(bench_revision "$1")
  driver=$(bench_driver)
  date_utc=$(date -u +%Y-%m-%dT%H:%MZ)
}

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

#   bench_prefix NAME DEVICE   a results file's prefix: NAME, else the date and a device slug
bench_prefix() {
  if [ -n "$1" ]; then
    echo "$1"
  else
    echo "$(date -u +%Y-%m-%d)-$(echo "$2" | tr -c 'A-Za-z0-9\n' '-' | tr -s '-' | cut -c1-24 | sed 's/-$//')"
  fi
}

#   bench_csv_header DEVICE COMMAND   the '# key: value' lines scripts/gen_bench_docs.py reads;
#   needs revision, driver and date_utc set (taken once, when the run starts)
bench_csv_header() {
  echo "# device: $1"
  echo "# driver: $driver"
  echo "# date: $date_utc"
  echo "# command: $2"
  echo "# git: $revision"
  echo "# host: $(nproc) CPUs, $(uname -sr), load average $(cut -d' ' -f1-3 /proc/loadavg)"
}

# Runs PROGRAM (BUILD/bench/KIND, or BUILD/$BENCH_DIR/KIND where BENCH_DIR
# is set, e.g. examples) PROCESSES times with ARGS, each time into a CSV
# whose rows get a leading process column, and writes them as one results
# file OUT/PREFIX-KIND.csv (PREFIX-$BENCH_LABEL.csv where that is set)
# headed by bench_csv_header. Needs bench_start first.
#   bench_processes BUILD OUT NAME KIND PROCESSES ARGS...
bench_processes() {
  local build=$1 out=$2 name=$3 kind=$4 processes=$5
  shift 5
  local dir=${BENCH_DIR:-bench}
  local program="$build/$dir/$kind" command="$dir/$kind${*:+ $*} --csv FILE"
  [ -x "$program" ] || { echo "$kind: no $program (build the $kind target first)" >&2; exit 1; }
  local body="$out/tmp-$kind-body.csv" csv="$out/tmp-$kind.csv" log="$out/tmp-$kind.log" device="" p
  : >"$body"
  for p in $(seq 1 "$processes"); do
    echo "== $command (process $p of $processes)" >&2
    "$program" "$@" --csv "$csv" | tee "$log"
    [ -n "$device" ] || device=$(sed -n 's/^device: \([^;]*\);.*/\1/p' "$log" | head -1)
    [ -s "$body" ] || head -1 "$csv" | sed 's/^/process,/' >"$body"
    tail -n +2 "$csv" | sed "s/^/$p,/" >>"$body"
  done
  local prefix
  prefix=$(bench_prefix "$name" "$device")
  {
    bench_csv_header "$device" "$command, $processes processes (Release build)"
    cat "$body"
  } >"$out/$prefix-${BENCH_LABEL:-$kind}.csv"
  rm -f "$body" "$csv" "$log"
  echo "wrote $out/$prefix-${BENCH_LABEL:-$kind}.csv" >&2
}
