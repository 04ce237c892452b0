#!/usr/bin/env bash
# contact-patch against DOLFINx 0.11 on the same problems and meshes, timed in one run:
#
#     bash crosscheck/performance.sh [DOFS]      (default 1000000; e.g. 50000 runs in a minute)
#
# builds our tool (cargo build --release; PERF_SKIP_BUILD=1 uses the binary already built),
# then crosscheck/performance.py solves the plane-strain square and the block on a rigid line
# (issue 14) with both codes, one process after the other, and writes reports/performance.md
# and reports/performance.json (times, peak memory, ratios; PERF_REPORTS=DIR writes there
# instead). Needs the environment crosscheck/run.sh creates (.venv-xcheck with DOLFINx); without
# it prints one line starting with "SKIPPED:" and exits 0. The run folder is a temporary one.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
DOFS="${1:-1000000}"
VENV="$ROOT/.venv-xcheck"
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c 'import dolfinx_solver, dolfinx' 2>/dev/null; then
    echo "SKIPPED: crosscheck/performance.sh: no DOLFINx environment in $VENV (run bash crosscheck/run.sh once to create it)"
    exit 0
fi
TARGET="${CARGO_TARGET_DIR:-$ROOT/target}"
if [ -z "${PERF_SKIP_BUILD:-}" ]; then
    cargo build --release -q
fi
BIN="$TARGET/release/contact-patch"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
PERF_PYTHON="$VENV/bin/python" "$VENV/bin/python" crosscheck/performance.py run "$BIN" "$WORK" \
    "${PERF_REPORTS:-$ROOT/reports}" --dofs "$DOFS"
echo "performance: wrote ${PERF_REPORTS:-reports}/performance.md and performance.json"
