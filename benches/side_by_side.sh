#!/usr/bin/env bash
# Side-by-side timing of two builds of contact-patch in one run (ratios, not absolute figures):
#
#     bash benches/side_by_side.sh OLD_REV [ROUNDS]
#
# builds OLD_REV in a temporary git worktree (or uses the binary in $OLD_BIN), builds this
# checkout, then alternates the two binaries ROUNDS times (default 3) on
#   - the patch and tied catalogues: `table cases/patch cases/tied` (wall time of the command),
#   - the 1M-dof square: `run cases/large/square-1m.json` (its summary.json `total`),
# and prints the median of each and the ratio new / old. Output goes to a temporary folder.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
OLD_REV="${1:?usage: side_by_side.sh OLD_REV [ROUNDS]}"
ROUNDS="${2:-3}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"; git -C "$ROOT" worktree remove --force "$WORK/old-src" 2>/dev/null || true' EXIT
if [ -z "${OLD_BIN:-}" ]; then
    git worktree add --detach "$WORK/old-src" "$OLD_REV" >/dev/null
    (cd "$WORK/old-src" && CARGO_TARGET_DIR="$ROOT/target/side-by-side-old" cargo build --release -q)
    OLD_BIN="$ROOT/target/side-by-side-old/release/contact-patch"
fi
cargo build --release -q
NEW_BIN="$ROOT/target/release/contact-patch"
declare -A T
for r in $(seq 1 "$ROUNDS"); do
    for which in old new; do
        bin=$OLD_BIN; [ "$which" = new ] && bin=$NEW_BIN
        out="$WORK/$which-$r"
        mkdir -p "$out"
        start=$(date +%s.%N)
        "$bin" table cases/patch cases/tied --out "$out/tables" > /dev/null
        end=$(date +%s.%N)
        T[$which-table-$r]=$(echo "$end - $start" | bc)
        "$bin" run cases/large/square-1m.json --out "$out/large" > /dev/null
        T[$which-large-$r]=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['timings']['total'])" "$out/large/summary.json")
        rm -rf "$out/large"
        echo "round $r $which: table ${T[$which-table-$r]} s, square-1m ${T[$which-large-$r]} s" >&2
    done
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
for job in table large; do
    old=$(median $(for r in $(seq 1 "$ROUNDS"); do echo "${T[old-$job-$r]}"; done))
    new=$(median $(for r in $(seq 1 "$ROUNDS"); do echo "${T[new-$job-$r]}"; done))
    printf '%-6s old %.3f s, new %.3f s, new/old %.3f (median of %d alternating rounds)\n' \
        "$job" "$old" "$new" "$(echo "$new / $old" | bc -l)" "$ROUNDS"
done
