#!/usr/bin/env bash
# Set up everything (npm packages, Debian chromium and speech tools, the Python venv) and run every suite:
# pytest (training toolkit), TypeScript typecheck, Vitest (unit + parity), Playwright (browser).
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
ensure_node_modules
ensure_chromium
ensure_venv
ensure_corpus_tools
cd "$REPO_ROOT"
failed=()
passed=0
step() {
  local name="$1"; shift
  say "── $name"
  local t0=$SECONDS
  if "$@"; then say "$name: ok ($((SECONDS - t0)) s)"; passed=$((passed + 1)); else say "$name: FAILED ($((SECONDS - t0)) s)"; failed+=("$name"); fi
}
step "pytest (training/)" bash -c 'cd training && PYTHONPATH="$1/training/src" "$2/bin/python" -m pytest -q' _ "$REPO_ROOT" "$TALKING_FACE_VENV"
step "typecheck (tsc)" npx tsc -p .
step "vitest" npx vitest run
step "playwright (headless chromium)" npx playwright test
[ ${#failed[@]} -eq 0 ] || say "failed suites: ${failed[*]}"
echo "suites: $passed passed, ${#failed[@]} failed"
[ ${#failed[@]} -eq 0 ]
