#!/usr/bin/env bash
# Everything the test suite needs, run inside the activated venv (the README's test command):
# 1. Debian's Chromium for the HTML report browser tests (tests/test_report_browser.py drives /usr/bin/chromium
#    with Playwright; no browser is downloaded). Skipped when present or VRUSIM_SKIP_BROWSER_TESTS=1; uses sudo
#    when not root.
# 2. vrusim with its test extra (every extra, and the test tools), editable.
# 3. The ASAM Quality Checkers for OpenSCENARIO XML and OpenDRIVE in a venv of their own, <this venv>/asam-qc
#    (tests/asam_qc.py runs them there): asam-qc-opendrive 1.0.0, the only release, pins numpy<2, which cannot
#    share an environment with vrusim's NumPy 2 and leave `pip check` passing (docs/interop.md).
set -euo pipefail

if [[ "${VRUSIM_SKIP_BROWSER_TESTS:-}" != "1" && ! -x /usr/bin/chromium ]]; then
  if [[ "$(id -u)" == "0" ]]; then
    as_root=()
  elif command -v sudo > /dev/null && sudo -n true 2> /dev/null; then
    as_root=(sudo -n)
  else
    echo "install-test-deps: /usr/bin/chromium is missing and this user cannot install packages;" >&2
    echo "  run 'sudo apt-get install chromium' or set VRUSIM_SKIP_BROWSER_TESTS=1 to skip the browser tests." >&2
    exit 1
  fi
  echo "install-test-deps: installing Debian's chromium package for the browser tests" >&2
  export DEBIAN_FRONTEND=noninteractive
  "${as_root[@]}" apt-get update -qq
  "${as_root[@]}" apt-get install -y -qq chromium > /dev/null
  /usr/bin/chromium --version >&2
fi

pip install -e ".[test]"

# earlier versions of this script installed the checkers here, next to vrusim
pip uninstall -y -q asam-qc-opendrive asam-qc-openscenarioxml 2> /dev/null || true
checkers="$(python -c 'import sys; print(sys.prefix)')/asam-qc"
python -m venv "$checkers"
"$checkers/bin/pip" install -q "asam-qc-opendrive==1.0.0" "asam-qc-openscenarioxml==1.0.0"
"$checkers/bin/pip" check
pip check
