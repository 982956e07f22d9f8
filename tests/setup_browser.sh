#!/usr/bin/env bash
# Installs Debian's chromium for tests/test_plotting_browser.py (the interactive page opened in a
# real headless browser). Does nothing when chromium is already there; says so and exits 0 when
# it cannot install (no apt-get, not root): the browser tests are then skipped, with the reason.
set -euo pipefail
if command -v chromium >/dev/null 2>&1; then
    echo "setup_browser: $(chromium --version 2>/dev/null || echo chromium) is installed"
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "setup_browser: no apt-get here; install chromium by hand or the browser tests are skipped" >&2
    exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        SUDO="sudo -n"
    else
        echo "setup_browser: not root and no sudo; the browser tests are skipped" >&2
        exit 0
    fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq chromium >/dev/null
echo "setup_browser: $(chromium --version 2>/dev/null || echo chromium) installed"
