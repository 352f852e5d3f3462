#!/usr/bin/env bash
# Installs what the browser test of `frenetic report` needs: Debian's chromium (apt-get) and
# playwright-core (npm ci from tests/report/package-lock.json, into tests/report/node_modules).
# Idempotent; without these tools the browser test skips (ctest reports it as skipped).
#   scripts/report-test-deps.sh
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
log() { printf '[report-test-deps] %s\n' "$*" >&2; }

sudo=()
[ "$(id -u)" -eq 0 ] || sudo=(sudo)

if [ ! -x /usr/bin/chromium ]; then
  log "installing chromium (Debian package)"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi

if ! command -v npm >/dev/null; then
  log "installing nodejs and npm (Debian packages)"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi

if [ ! -d "$ROOT/tests/report/node_modules/playwright-core" ]; then
  log "installing playwright-core (npm ci, pinned by tests/report/package-lock.json)"
  # playwright-core downloads no browser itself; the test uses /usr/bin/chromium.
  (cd "$ROOT/tests/report" && npm ci --no-audit --no-fund --loglevel=error)
fi
log "ready: $(/usr/bin/chromium --version 2>/dev/null || echo 'chromium missing'), playwright-core $(
  node -p "require('$ROOT/tests/report/node_modules/playwright-core/package.json').version")"
