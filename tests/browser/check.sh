#!/usr/bin/env bash
# The browser test of the HTML report (issue 16 item 7), from anywhere in the repository:
#
#     bash tests/browser/check.sh [REPORTS_DIR]      (default: reports)
#
# 1. writes REPORTS_DIR/index.html with our tool (`contact-patch report`; builds the tool if
#    its release binary is missing);
# 2. finds Debian's `chromium`; when it is missing and we run as root, installs it
#    (apt-get update && apt-get install -y chromium); otherwise prints one line starting with
#    "SKIPPED:" and exits 0;
# 3. opens the page in headless Chromium from the file system (file://): a screenshot
#    (REPORTS_DIR/index.png, 1280x2000) and the DOM after loading (--dump-dom), with the
#    console on stderr;
# 4. checks them with tests/browser/check_page.py (tables rendered, every link and image
#    resolves, no image failed to load, no script error). Exit 1 when a check fails.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$ROOT"
REPORTS="${1:-reports}"

TOOL="${CARGO_TARGET_DIR:-$ROOT/target}/release/contact-patch"
if [ ! -x "$TOOL" ]; then
    cargo build --release -q
fi
"$TOOL" report --reports "$REPORTS"

find_chromium() {
    for c in chromium chromium-browser; do
        if command -v "$c" >/dev/null 2>&1; then
            command -v "$c"
            return 0
        fi
    done
    return 1
}
CHROMIUM="$(find_chromium || true)"
if [ -z "$CHROMIUM" ]; then
    if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then
        echo "browser: installing Debian's chromium (apt-get)"
        if ! { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; } \
            >/tmp/contact-patch-apt-chromium.log 2>&1; then
            echo "SKIPPED: browser test: apt-get install chromium failed (log: /tmp/contact-patch-apt-chromium.log)"
            exit 0
        fi
        CHROMIUM="$(find_chromium || true)"
    fi
fi
if [ -z "$CHROMIUM" ]; then
    echo "SKIPPED: browser test: no chromium on PATH and cannot install it (not root, or no apt-get)"
    exit 0
fi

PAGE="$(cd "$REPORTS" && pwd)/index.html"
SHOT="$(cd "$REPORTS" && pwd)/index.png"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
FLAGS=(--headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$TMP/profile")
"$CHROMIUM" "${FLAGS[@]}" --screenshot="$SHOT" --window-size=1280,2000 "file://$PAGE" \
    >"$TMP/shot.log" 2>&1 || { cat "$TMP/shot.log" >&2; exit 1; }
"$CHROMIUM" "${FLAGS[@]}" --enable-logging=stderr --v=0 --virtual-time-budget=10000 \
    --dump-dom "file://$PAGE" >"$TMP/dom.html" 2>"$TMP/console.log" \
    || { cat "$TMP/console.log" >&2; exit 1; }
python3 tests/browser/check_page.py "$PAGE" "$TMP/dom.html" "$TMP/console.log" "$SHOT"
