#!/usr/bin/env bash
# Runs every cargo-fuzz target (fuzz/fuzz_targets/) with the limits of docs/reliability.md:
#   tools/fuzz_all.sh [SECONDS_PER_TARGET (default 600)] [RUNS (default 10000000)] [TARGET...]
# New corpus entries go to fuzz/corpus-live/<target> (ignored by git); the committed seeds in
# fuzz/corpus/<target> are only read. Logs: fuzz/logs/<target>.log; crashes: fuzz/artifacts/.
# Needs a nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-600}; runs=${2:-10000000}; shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(gltf glb gltf_extras settings_toml cube lut_strip_png probe_bake)
cargo +nightly fuzz build -a
mkdir -p fuzz/logs
for t in "${targets[@]}"; do
  mkdir -p "fuzz/corpus-live/$t"
  # One process a target (no -jobs/-workers); RAYON_NUM_THREADS=1 keeps the BVH build on it.
  RAYON_NUM_THREADS=1 cargo +nightly fuzz run -a "$t" "fuzz/corpus-live/$t" "fuzz/corpus/$t" -- \
    -rss_limit_mb=1024 -malloc_limit_mb=1024 -timeout=1 -runs="$runs" -max_total_time="$secs" \
    -print_final_stats=1 > "fuzz/logs/$t.log" 2>&1 || echo "$t: libFuzzer stopped with a finding, see fuzz/logs/$t.log"
  grep -E "^#[0-9]+.*(DONE|pulse)" "fuzz/logs/$t.log" | tail -1 | sed "s/^/$t: /"
done
