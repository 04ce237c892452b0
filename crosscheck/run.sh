#!/usr/bin/env bash
# The cross-check in one command (from anywhere in the repository):
#
#     bash crosscheck/run.sh [CASE.json ...]
#
# 1. finds Python 3.12 (pyenv's newest 3.12.x, else python3.12 on PATH); without it prints one
#    line starting with "SKIPPED:" and exits 0;
# 2. creates .venv-xcheck (repository root, git-ignored) if missing or not 3.12, and installs
#    crosscheck/requirements.txt into it unless that exact file is already installed;
# 3. builds our tool (cargo build --release; XCHECK_SKIP_BUILD=1 uses the binary already in
#    target/release) and runs every case into a temporary folder (kept when XCHECK_OUT=DIR);
# 4. solves the same cases on the meshes our tool wrote with DOLFINx and scikit-fem;
# 5. judges DOLFINx's own .vtu output of each case with `contact-patch judge` (the case's
#    checks applied to an outside code's results, JUnit in the run folder);
# 6. without CASE arguments, the peer code: Kratos Multiphysics (.venv-kratos, pinned in
#    crosscheck/requirements-kratos.txt; "SKIPPED:" when it cannot be installed) solves the
#    contact and tied patch tests and Hertz's cylinder, judged by our tool
#    (crosscheck/peer_kratos.py -> reports/peer-codes.md and .json; XCHECK_SKIP_PEER=1 skips);
# 7. writes reports/crosscheck.md and reports/crosscheck.json; exits 1 when any verdict fails
#    (or when the peer step broke: our tool crashed or a script failed; Kratos failing a cell
#    is a result in reports/peer-codes.md, not a failure of the run).
#
# Default cases: cases/patch-single, cases/convergence (single-body elasticity),
# crosscheck/cases (cross-check-only elasticity cases), crosscheck/cases/contact (penalty
# contact with rigid surfaces), crosscheck/cases/friction (penalty Coulomb contact on a rigid
# line in two load steps, DOLFINx only), crosscheck/cases/dynamics (elastic waves in a bar, stepped by
# DOLFINx with the same mesh, mass and Newmark parameters), crosscheck/cases/finite (finite
# kinematics: hyperelastic cantilevers and a neo-Hookean block pressed onto a rigid line with a
# penalty, DOLFINx only, the same load steps), in 3D cases/3d (uniform-stress patch tests on
# Hex8, Hex27, Tet4, Tet10) and crosscheck/cases/3d (a clamped block under two pressures on
# distorted meshes, and a rigid sphere pressed into a block with penalty rows, all four
# elements), and the studies that crosscheck/studies.py generates into the
# run folder: the tied layer (cases/tied-layer at levels 1, 2, 4, 8) and the two blocks
# (crosscheck/cases/two-block at levels 1, 2, 4, and its fine one-body reference). With CASE
# arguments only those cases run (no studies).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
SECONDS=0
VENV="$ROOT/.venv-xcheck"
REQ="$ROOT/crosscheck/requirements.txt"

# --- 1. Python 3.12 ---------------------------------------------------------------------------
PY312=""
PYENV_ROOT_DIR="${PYENV_ROOT:-$HOME/.pyenv}"
if command -v pyenv >/dev/null 2>&1; then
    PYENV_ROOT_DIR="$(pyenv root)"
fi
if [ -d "$PYENV_ROOT_DIR/versions" ]; then
    v="$(ls "$PYENV_ROOT_DIR/versions" | grep -E '^3\.12\.[0-9]+$' | sort -V | tail -n 1 || true)"
    if [ -n "$v" ] && [ -x "$PYENV_ROOT_DIR/versions/$v/bin/python3" ]; then
        PY312="$PYENV_ROOT_DIR/versions/$v/bin/python3"   # = PYENV_VERSION=$v python3
    fi
fi
if [ -z "$PY312" ] && command -v python3.12 >/dev/null 2>&1; then
    PY312="$(command -v python3.12)"
fi
if [ -z "$PY312" ]; then
    echo "SKIPPED: crosscheck: no Python 3.12 interpreter (none in pyenv's versions under $PYENV_ROOT_DIR, no python3.12 on PATH); DOLFINx 0.11 wheels need Python 3.12"
    exit 0
fi

# --- 2. the environment -----------------------------------------------------------------------
is312() { "$1" -c 'import sys; sys.exit(0 if sys.version_info[:2] == (3, 12) else 1)' 2>/dev/null; }
if [ ! -x "$VENV/bin/python" ] || ! is312 "$VENV/bin/python"; then
    echo "crosscheck: creating $VENV with $PY312"
    rm -rf "$VENV"
    "$PY312" -m venv "$VENV"
fi
STAMP="$VENV/.xcheck-requirements.sha256"
WANT="$(sha256sum "$REQ" | cut -d' ' -f1)"
if [ "$(cat "$STAMP" 2>/dev/null || true)" != "$WANT" ]; then
    echo "crosscheck: installing crosscheck/requirements.txt"
    "$VENV/bin/python" -m pip install --disable-pip-version-check -q -r "$REQ"
    echo "$WANT" > "$STAMP"
fi
PY="$VENV/bin/python"

# --- 3. our tool -------------------------------------------------------------------------------
TOOL="${CARGO_TARGET_DIR:-$ROOT/target}/release/contact-patch"
XCHECK_OURS_VERSION="$(git describe --always --dirty 2>/dev/null || echo unknown)"
if [ -z "${XCHECK_SKIP_BUILD:-}" ]; then
    cargo build --release -q
else
    XCHECK_OURS_VERSION="prebuilt target/release binary of $(date -u -r "$TOOL" '+%Y-%m-%d %H:%M UTC'); tree now $XCHECK_OURS_VERSION"
fi
export XCHECK_OURS_VERSION
if [ -n "${XCHECK_OUT:-}" ]; then
    OUT="$XCHECK_OUT"
    mkdir -p "$OUT"
else
    OUT="$(mktemp -d "${TMPDIR:-/tmp}/xcheck.XXXXXX")"
    trap 'rm -rf "$OUT"' EXIT
fi
if [ "$#" -gt 0 ]; then
    CASES=("$@")
    rm -f "$OUT/studies.json"
else
    CASES=(cases/patch-single/*.json cases/convergence/*.json crosscheck/cases/*.json
           crosscheck/cases/contact/*.json crosscheck/cases/friction/*.json
           crosscheck/cases/dynamics/*.json crosscheck/cases/finite/*.json
           cases/3d/*.json crosscheck/cases/3d/*.json)
    "$PY" crosscheck/studies.py "$OUT" > "$OUT/study-cases.txt"
    mapfile -t STUDY_CASES < "$OUT/study-cases.txt"
    CASES+=("${STUDY_CASES[@]}")
fi
dups="$(for c in "${CASES[@]}"; do basename "$c" .json; done | sort | uniq -d)"
if [ -n "$dups" ]; then
    echo "crosscheck: two cases share a file name: $dups" >&2
    exit 1
fi
for c in "${CASES[@]}"; do
    name="$(basename "$c" .json)"
    rc=0
    "$TOOL" run "$c" --out "$OUT/$name" > "$OUT/$name.log" 2>&1 || rc=$?
    # 1 = one of the case's own checks failed (output still written); 2 = no solution.
    if [ "$rc" -ge 2 ]; then
        echo "crosscheck: our tool failed on $c (exit $rc):" >&2
        cat "$OUT/$name.log" >&2
    fi
done
echo "crosscheck: our tool ran ${#CASES[@]} cases ($SECONDS s so far)"

# --- 4. the references --------------------------------------------------------------------------
# Their own failures are recorded in the reference files and fail the verdicts in step 5.
"$PY" crosscheck/ref_dolfinx.py "$OUT" "${CASES[@]}" > "$OUT/dolfinx.log" 2>&1 \
    || { echo "crosscheck: DOLFINx reported errors:" >&2; cat "$OUT/dolfinx.log" >&2; }
"$PY" crosscheck/ref_skfem.py "$OUT" "${CASES[@]}" > "$OUT/skfem.log" 2>&1 \
    || { echo "crosscheck: scikit-fem reported errors:" >&2; cat "$OUT/skfem.log" >&2; }

# --- 5. DOLFINx's results judged by our tool ------------------------------------------------------
for c in "${CASES[@]}"; do
    name="$(basename "$c" .json)"
    vtu="$OUT/$name/dolfinx_p0_000000.vtu"
    [ -f "$vtu" ] || continue
    rc=0
    "$TOOL" judge "$c" "$vtu" --junit "$OUT/$name/judge-dolfinx.xml" \
        > "$OUT/$name/judge-dolfinx.txt" 2>&1 || rc=$?
    echo "$rc" > "$OUT/$name/judge-dolfinx.rc"
done

# --- 6. the peer code: Kratos on the patch, tied and Hertz cases ---------------------------------
# Only in the default run (no CASE arguments), unless XCHECK_SKIP_PEER=1. Its own environment,
# .venv-kratos (crosscheck/requirements-kratos.txt, the same Python 3.12); when it cannot be
# installed, one "SKIPPED:" line and the rest of the cross-check goes on. Kratos failing a cell
# is recorded in reports/peer-codes.md; our tool crashing or a broken script fails the run.
PEER_RC=0
if [ "$#" -eq 0 ] && [ -z "${XCHECK_SKIP_PEER:-}" ]; then
    PEER_START=$SECONDS
    KVENV="$ROOT/.venv-kratos"
    KREQ="$ROOT/crosscheck/requirements-kratos.txt"
    KSTAMP="$KVENV/.xcheck-requirements.sha256"
    KWANT="$(sha256sum "$KREQ" | cut -d' ' -f1)"
    kratos_ready=1
    if [ ! -x "$KVENV/bin/python" ] || ! is312 "$KVENV/bin/python"; then
        echo "crosscheck: creating $KVENV with $PY312"
        rm -rf "$KVENV"
        "$PY312" -m venv "$KVENV" || kratos_ready=0
    fi
    if [ "$kratos_ready" = 1 ] && [ "$(cat "$KSTAMP" 2>/dev/null || true)" != "$KWANT" ]; then
        echo "crosscheck: installing crosscheck/requirements-kratos.txt"
        if "$KVENV/bin/python" -m pip install --disable-pip-version-check -q -r "$KREQ" \
                > "$OUT/kratos-install.log" 2>&1; then
            echo "$KWANT" > "$KSTAMP"
        else
            kratos_ready=0
        fi
    fi
    if [ "$kratos_ready" = 1 ] && ! "$KVENV/bin/python" -c \
            'import KratosMultiphysics.ContactStructuralMechanicsApplication' > /dev/null 2>&1; then
        kratos_ready=0
    fi
    if [ "$kratos_ready" = 1 ]; then
        "$KVENV/bin/python" crosscheck/peer_kratos.py "$TOOL" "$KVENV/bin/python" "$OUT/peer" \
            reports > "$OUT/peer.log" 2>&1 || PEER_RC=$?
        if [ "$PEER_RC" -ne 0 ]; then
            echo "crosscheck: the peer-code check broke (exit $PEER_RC):" >&2
            tail -n 40 "$OUT/peer.log" >&2
        fi
        echo "crosscheck: peer code Kratos took $((SECONDS - PEER_START)) s (reports/peer-codes.md)"
    else
        echo "SKIPPED: crosscheck: Kratos (crosscheck/requirements-kratos.txt) could not be installed or imported in $KVENV; reports/peer-codes.md not regenerated (see $OUT/kratos-install.log)"
    fi
fi

# --- 7. the verdicts ------------------------------------------------------------------------------
echo "$SECONDS" > "$OUT/elapsed"
rc=0
"$PY" crosscheck/report.py "$OUT" reports/crosscheck.md reports/crosscheck.json "${CASES[@]}" || rc=$?
[ "$PEER_RC" -eq 0 ] || exit 1
exit "$rc"
