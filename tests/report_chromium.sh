#!/usr/bin/env bash
# End-to-end check of a deadreckon HTML report in headless Chromium (Debian's
# `chromium` package):
#   1. loads the page offline and dumps the DOM after its scripts ran; the report's
#      inline self-check has written into <div id="selfcheck"> whether every
#      <figure> drew data (an element with a non-empty bounding box inside the
#      figure's <g class="data">) and whether any script error, console.error or
#      blocked load happened;
#   2. scans Chromium's log of the page console for uncaught errors;
#   3. takes a screenshot.
#
# Usage: tests/report_chromium.sh REPORT.html OUT.png [WINDOW_HEIGHT_PX]
# Also writes OUT-<section>.png, one screenshot per report section.
# Exit status: 0 when every figure has data and there are no errors, 1 otherwise,
# 2 on bad usage or when Chromium is missing.
set -euo pipefail

if [[ $# -lt 2 ]]; then
    echo "usage: $0 REPORT.html OUT.png [WINDOW_HEIGHT_PX]" >&2
    exit 2
fi
html=$(realpath "$1")
png=$(realpath -m "$2")
height=${3:-14000}
[[ -f $html ]] || { echo "no such report: $html" >&2; exit 2; }

chromium_bin=${CHROMIUM:-}
if [[ -z $chromium_bin ]]; then
    for c in chromium chromium-browser google-chrome; do
        if command -v "$c" >/dev/null 2>&1; then chromium_bin=$c; break; fi
    done
fi
[[ -n $chromium_bin ]] || { echo "chromium not found (apt-get install -y chromium)" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run_chromium() {
    # A fresh profile per run; every background service that could reach the network is off.
    timeout 120 "$chromium_bin" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --disable-dev-shm-usage --hide-scrollbars \
        --user-data-dir="$(mktemp -d -p "$work")" \
        --enable-logging=stderr --v=0 "$@"
}

run_chromium --dump-dom "file://$html" >"$work/dom.html" 2>"$work/dom.log" || {
    echo "chromium --dump-dom failed:" >&2
    tail -n 20 "$work/dom.log" >&2
    exit 1
}
run_chromium --screenshot="$png" --window-size="1280,$height" "file://$html" >"$work/shot.out" 2>"$work/shot.log" || {
    echo "chromium --screenshot failed:" >&2
    tail -n 20 "$work/shot.log" >&2
    exit 1
}

status=0
check=$(grep -o '<div id="selfcheck"[^>]*>' "$work/dom.html" || true)
if [[ -z $check ]]; then
    echo "FAIL: no #selfcheck element in the rendered DOM" >&2
    status=1
else
    attr() { sed -n "s/.* $1=\"\([^\"]*\)\".*/\1/p" <<<"$check"; }
    ok=$(attr data-ok)
    echo "selfcheck: ok=$ok figures=$(attr data-figures) drawn-elements=$(attr data-elements)"
    if [[ $ok != true ]]; then
        echo "FAIL: figures without data: [$(attr data-empty)]; errors: [$(attr data-errors)]" >&2
        status=1
    fi
    if [[ $(attr data-figures) == 0 ]]; then
        echo "FAIL: the report has no figure" >&2
        status=1
    fi
fi
# Console messages of the page appear as "CONSOLE" lines in Chromium's log.
if grep -h 'CONSOLE' "$work/dom.log" "$work/shot.log" | grep -Ei 'uncaught|error' >"$work/console.txt"; then
    echo "FAIL: console errors:" >&2
    cat "$work/console.txt" >&2
    status=1
fi
if [[ ! -s $png ]]; then
    echo "FAIL: no screenshot written" >&2
    status=1
else
    echo "screenshot: $png"
fi
# Chromium draws nothing below about 16k pixels of a headless screenshot, so a
# long report is also shot one section at a time (the others hidden), for people
# to look at: OUT-<section>.png.
for id in $(grep -o '<section id="[a-z0-9-]*"' "$html" | sed 's/.*id="\([^"]*\)"/\1/'); do
    one="$work/section-$id.html"
    sed "s#</head>#<style>section:not(\#$id){display:none !important}</style></head>#" "$html" >"$one"
    shot="${png%.png}-$id.png"
    if run_chromium --screenshot="$shot" --window-size="1280,$height" "file://$one" >/dev/null 2>&1 && [[ -s $shot ]]; then
        echo "section screenshot: $shot"
    else
        echo "FAIL: no screenshot of section $id" >&2
        status=1
    fi
done
exit $status
