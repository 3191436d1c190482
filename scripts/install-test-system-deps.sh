#!/usr/bin/env bash
# System packages the test suite needs beyond pip: Debian's Chromium for the HTML report browser tests
# (tests/test_report_browser.py drives /usr/bin/chromium with Playwright; no browser is downloaded).
# Does nothing when Chromium is already there or VRUSIM_SKIP_BROWSER_TESTS=1; uses sudo when not root.
set -euo pipefail

if [[ "${VRUSIM_SKIP_BROWSER_TESTS:-}" == "1" || -x /usr/bin/chromium ]]; then
  exit 0
fi
if [[ "$(id -u)" == "0" ]]; then
  as_root=()
elif command -v sudo > /dev/null && sudo -n true 2> /dev/null; then
  as_root=(sudo -n)
else
  echo "install-test-system-deps: /usr/bin/chromium is missing and this user cannot install packages;" >&2
  echo "  run 'sudo apt-get install chromium' or set VRUSIM_SKIP_BROWSER_TESTS=1 to skip the browser tests." >&2
  exit 1
fi
echo "install-test-system-deps: installing Debian's chromium package for the browser tests" >&2
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq chromium > /dev/null
/usr/bin/chromium --version >&2
