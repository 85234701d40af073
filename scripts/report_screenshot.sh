#!/usr/bin/env bash
# Renders a report's self-contained report.html in a headless browser and saves a screenshot,
# to check that it renders. Needs Debian's chromium:
#   apt-get install --no-install-recommends chromium
# Usage: scripts/report_screenshot.sh REPORT_DIR [OUT.png] [HEIGHT_PX]
set -euo pipefail
dir=$(cd "$1" && pwd)
out=${2:-$dir/report_screenshot.png}
height=${3:-6000}
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [[ -z "$browser" ]]; then
    echo "no chromium found: apt-get install --no-install-recommends chromium" >&2
    exit 2
fi
[[ -f "$dir/report.html" ]] || { echo "$dir/report.html: no such file" >&2; exit 2; }
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --window-size=1200,"$height" --screenshot="$out" "file://$dir/report.html" 2>/dev/null
[[ -s "$out" ]] || { echo "no screenshot written" >&2; exit 1; }
echo "$out"
