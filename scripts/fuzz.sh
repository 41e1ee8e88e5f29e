#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/) with clang, ASan and UBSan (scripts/sanitize-build.sh, in
# build-sanitize/, the tree the sanitized tests use too) and runs each for
# SECONDS (default 60) on a corpus seeded from the project's own files (data/, a simulated
# trajectory, hand-written configs) and, when present, ../shared's MIT sample. A finding (crash,
# sanitizer report, leak, timeout) stops that harness and leaves crash-*/leak-*/timeout-* in
# out/fuzz/TARGET/; the script then exits 1 after running the others. fuzz/README.md has more.
#
#   bash scripts/fuzz.sh                  # every harness, 60 s each
#   SECONDS_EACH=600 bash scripts/fuzz.sh fuzz_shape_json fuzz_mit_hdf5
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${SECONDS_EACH:-60}
SHARED_DIR=${SHARED_DIR:-../shared}
BUILD=${FUZZ_BUILD_DIR:-build-sanitize}
OUT=${FUZZ_OUT:-out/fuzz}
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_shape_json fuzz_trajectory_json fuzz_points_csv fuzz_obj_footprint
                                     fuzz_mit_hdf5 fuzz_mit_json fuzz_estimator_config fuzz_evaluation_config)
# The tool only makes a seed: the main build's when there is one.
P=${PUSHGRAPH:-build/tools/pushgraph}
tool_target=()
[ -x "$P" ] || { P="$BUILD/tools/pushgraph"; tool_target=(pushgraph); }
SANITIZE_BUILD_DIR="$BUILD" bash scripts/sanitize-build.sh "${targets[@]}" "${tool_target[@]}"

# Seeds: the project's own files, and what the tool makes (the trajectory format).
seeds="$OUT/seeds"
rm -rf "$seeds"
mkdir -p "$seeds"/{shape,trajectory,points,obj,h5,mitjson,estimator,evaluation}
cp data/shapes/*.json "$seeds/shape/"
ASAN_OPTIONS=detect_leaks=0 "$P" simulate -o "$seeds/trajectory/sim.json" --rate-object 10 \
  --rate-finger 20 --rate-contact 20 --rate-force 20 --distance 0.01 > /dev/null
printf 'x,y\n0.01,-0.02\n0x1p-3, 4e-3\n\n1,2\n' > "$seeds/points/points.csv"
cp data/meshes/*.obj "$seeds/obj/"
if [ -d "$SHARED_DIR/data/mit-push" ]; then
  cp "$SHARED_DIR"/data/mit-push/obj/*.obj "$seeds/obj/" 2> /dev/null || true
  find "$SHARED_DIR/data/mit-push/abs" -name '*.h5' | sort | head -2 | while read -r f; do cp "$f" "$seeds/h5/"; done
fi
printf '{"tip_pose": [[0.0, 0.1, 0.0, 0.0], [0.01, 0.1, 0.01, 0.0]],\n "object_pose": [[0.0, 0.0, 0.0, 0.1], [0.01, 0.0, 0.01, 0.1]],\n "ft_wrench": [[0.0, 1.0, 0.0, 0.0], [0.01, 1.0, 0.1, 0.0]]}\n' \
  > "$seeds/mitjson/rec.json"
printf '{"graph": "qs", "mode": "batch", "solver": "chain"}\n' > "$seeds/estimator/a.json"
printf '{"graph": "cp", "mode": "incremental", "incremental_update_every_steps": 1, "finger_angle_resolution": 0.01}\n' > "$seeds/estimator/b.json"
printf '{"objects": {"ellip1": {"shape": "data/shapes/notched_block.json", "mass": 0.8, "mu_surface": 0.25}},\n "finger": "data/shapes/disk_finger_5mm.json", "mu_contact": 0.3, "estimator": {"graph": "qs"}}\n' \
  > "$seeds/evaluation/a.json"
seed_of() {
  case "$1" in
    fuzz_shape_json) echo shape ;; fuzz_trajectory_json) echo trajectory ;; fuzz_points_csv) echo points ;;
    fuzz_obj_footprint) echo obj ;; fuzz_mit_hdf5) echo h5 ;; fuzz_mit_json) echo mitjson ;;
    fuzz_estimator_config) echo estimator ;; fuzz_evaluation_config) echo evaluation ;;
  esac
}

# allocator_may_return_null: a C library's malloc that fails is its to handle (HDF5's metadata cache
# asks for what a corrupt header claims, 378 GB in one finding, and reports the failure, as it does
# with glibc); our own code's failed allocations still surface as std::bad_alloc, a finding.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"
failed=()
for t in "${targets[@]}"; do
  dir="$OUT/$t"
  mkdir -p "$dir/corpus"
  cp -n "$seeds/$(seed_of "$t")"/* "$dir/corpus/" 2> /dev/null || true
  echo "fuzz: $t for $SECONDS_EACH s (corpus $(ls "$dir/corpus" | wc -l) files)"
  # libFuzzer stops at any single malloc over -malloc_limit_mb (default: the RSS limit); HDF5's
  # metadata allocations are let through to fail inside the library (above).
  limits=(-rss_limit_mb=4096)
  [ "$t" != fuzz_mit_hdf5 ] || limits+=(-malloc_limit_mb=4194304)
  if ! (cd "$dir" && "$OLDPWD/$BUILD/fuzz/$t" -max_total_time="$SECONDS_EACH" -timeout=20 "${limits[@]}" \
          -max_len=262144 -print_final_stats=1 corpus > log.txt 2>&1); then
    failed+=("$t")
    echo "fuzz: $t FOUND something: $dir/log.txt"; grep -E "ERROR|SUMMARY|finding|Test unit written" "$dir/log.txt" | head -5
  else
    grep -E "stat::number_of_executed_units|cov:" "$dir/log.txt" | tail -2 | tr '\n' ' '; echo
  fi
done
[ ${#failed[@]} -eq 0 ] || { echo "fuzz: findings in ${failed[*]}"; exit 1; }
echo "fuzz: no finding in ${#targets[@]} harnesses, $SECONDS_EACH s each"
