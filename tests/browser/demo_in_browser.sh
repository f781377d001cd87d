#!/usr/bin/env bash
# The demo gallery in a headless browser: runs `priormap demo --quick --no-real`, opens
# index.html in Chromium and checks that the page loads, that every image in it loaded, and that
# the browser logged no console error. Exits 77 (skipped) when Chromium is not installed.
#   demo_in_browser.sh PRIORMAP WORK_DIR CHECK_PAGE
set -euo pipefail
priormap=$1 work=$2 check_page=$3
browser=$(command -v chromium || command -v chromium-browser || true)
if [[ -z "$browser" ]]; then
  echo "SKIP: no chromium (Debian package 'chromium', installed by scripts/install-deps.sh --tests)"
  exit 77
fi
rm -rf "$work" && mkdir -p "$work"
"$priormap" demo --quick --no-real --out "$work/demo" >"$work/demo.out"
cp "$check_page" "$work/demo/gallery_check.html"
# --no-sandbox: CI runs as root; --disable-dev-shm-usage: containers with a small /dev/shm; file
# access between file:// pages lets the check read the frame.
"$browser" --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --allow-file-access-from-files \
  --enable-logging=stderr --v=0 --virtual-time-budget=20000 \
  --dump-dom "file://$(realpath "$work/demo/gallery_check.html")" \
  >"$work/dom.html" 2>"$work/browser.log" || { cat "$work/browser.log"; exit 1; }
result=$(grep -o 'GALLERY-CHECK [a-z]*=[^<]*' "$work/dom.html" | grep -v '\${' | head -1 || true)
echo "$result"
[[ "$result" == *"title=priormap_demo "* ]] || { echo "FAIL: the gallery did not load"; exit 1; }
images=$(sed -n 's/.* images=\([0-9]*\).*/\1/p' <<<"$result")
[[ "$images" -ge 11 ]] || { echo "FAIL: expected at least 11 images, found $images"; exit 1; }
[[ "$result" == *" broken=0 "* ]] || { echo "FAIL: images did not load"; exit 1; }
# The gallery runs no script and the check page logs nothing: any console line is an error
# (uncaught exceptions and console.error calls both appear as CONSOLE lines).
if grep -E ':CONSOLE[:(]' "$work/browser.log"; then
  echo "FAIL: console messages (above)"
  exit 1
fi
echo "PASS: the gallery loaded with its $images images and no console error"
