#!/usr/bin/env bash
# Runs every cargo-fuzz target in fuzz/ (docs/reliability.md, "Fuzzing") for a bounded time
# each, one after another, one process each, and exits non-zero if any found a crash, a
# timeout or an out-of-memory input (kept under fuzz/artifacts/TARGET/). Installs the nightly
# toolchain and cargo-fuzz when missing. CI does not call it.
#
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
#   SECONDS_PER_TARGET  default 60; the first build takes about 4 minutes more (the tables
#                       crate generates its stencil tables once per fuzz build folder)
#   TARGET              default: obj bezier rates table rational
# Each run starts from the committed seeds (fuzz/seeds/TARGET) and the corpus the earlier runs
# grew (fuzz/corpus/TARGET, not committed); its output is in fuzz/logs/TARGET.log.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${1:-60}"
shift || true
targets=("$@")
all=(obj bezier rates table rational)
if [ ${#targets[@]} -eq 0 ]; then
    targets=("${all[@]}")
fi
case "$seconds" in
'' | *[!0-9]*)
    echo "usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]" >&2
    exit 2
    ;;
esac

if ! cargo +nightly --version >/dev/null 2>&1; then
    rustup toolchain install nightly --profile minimal
fi
if ! cargo +nightly fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi

# The workspace forbids unsafe code, so the sanitizer has little to find and halves the speed;
# debug assertions turn integer overflow into a crash.
build_flags=(--sanitizer none --debug-assertions)
# The libFuzzer limits (docs/reliability.md): inputs up to 64 KiB (128 KiB for tables: a
# butterfly table of one valence with all its regions is 85 KiB), 4 GiB of memory (a larger
# allocation is an out-of-memory crash), 10 s per input.
limits=(-rss_limit_mb=4096 -malloc_limit_mb=4096 -timeout=10 -print_final_stats=1)
max_len() {
    if [ "$1" = table ]; then echo 131072; else echo 65536; fi
}

if [ ${#targets[@]} -eq ${#all[@]} ]; then
    cargo +nightly fuzz build "${build_flags[@]}"
else
    for target in "${targets[@]}"; do
        cargo +nightly fuzz build "${build_flags[@]}" "$target"
    done
fi

mkdir -p fuzz/logs
failed=()
for target in "${targets[@]}"; do
    mkdir -p "fuzz/corpus/$target"
    echo "fuzzing $target for $seconds s (log: fuzz/logs/$target.log)"
    if cargo +nightly fuzz run "${build_flags[@]}" "$target" "fuzz/corpus/$target" "fuzz/seeds/$target" \
        -- "${limits[@]}" -max_len="$(max_len "$target")" -max_total_time="$seconds" >"fuzz/logs/$target.log" 2>&1; then
        grep -E '^#[0-9]+[[:space:]]+DONE' "fuzz/logs/$target.log" | tail -1 || true
    else
        echo "$target FAILED: see fuzz/logs/$target.log and fuzz/artifacts/$target/" >&2
        grep -E 'panicked|ERROR: libFuzzer|Test unit written' "fuzz/logs/$target.log" | head -5 >&2 || true
        failed+=("$target")
    fi
done

if [ ${#failed[@]} -ne 0 ]; then
    echo "crashes found in: ${failed[*]}" >&2
    exit 1
fi
echo "no crash in ${targets[*]} ($seconds s each)"
