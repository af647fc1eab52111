# Installs what the project needs, only what is missing. Sourced by demo.sh,
# test-all.sh and py; each ensure_* function is safe to call repeatedly.
set -euo pipefail

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# The Python venv (PyTorch is ~5 GB) lives outside the checkout so fresh clones share it.
TALKING_FACE_VENV="${TALKING_FACE_VENV:-$HOME/.cache/talking-face/venv}"
CHROMIUM_PATH="${CHROMIUM_PATH:-/usr/bin/chromium}"
# Debian packages: chromium for the browser tests; the corpus tools (TTS, alignment input, audio) for training.
APT_PACKAGES_BROWSER=(chromium)

say() { printf '\033[1m[setup]\033[0m %s\n' "$*" >&2; }

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"
  elif command -v sudo >/dev/null; then sudo "$@"
  else say "need root to run: $*"; return 1
  fi
}

ensure_apt() {
  local missing=()
  for p in "$@"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
  [ ${#missing[@]} -eq 0 ] && return 0
  say "installing Debian packages: ${missing[*]}"
  as_root apt-get update -qq
  # One retry: a mirror occasionally drops an archive mid-fetch.
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null ||
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

ensure_node_modules() {
  cd "$REPO_ROOT"
  command -v npm >/dev/null || { say "Node.js 20+ with npm is required (https://nodejs.org)"; return 1; }
  local stamp=node_modules/.talking-face-lock
  local want
  want="$(sha256sum package-lock.json | cut -d' ' -f1)"
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then return 0; fi
  say "installing npm packages (npm ci)"
  ONNXRUNTIME_NODE_INSTALL=skip npm ci --no-audit --no-fund --loglevel=error
  echo "$want" >"$stamp"
}

ensure_chromium() {
  if [ -x "$CHROMIUM_PATH" ]; then return 0; fi
  ensure_apt "${APT_PACKAGES_BROWSER[@]}"
  [ -x "$CHROMIUM_PATH" ] || { say "chromium is not at $CHROMIUM_PATH after installing; set CHROMIUM_PATH"; return 1; }
}

# The corpus's speech tools (festival, flite, espeak-ng, sox, recorded speech): the list lives in
# training/src/talkingface/corpus/speech.py; its setup command installs what is missing. Needs the venv.
ensure_corpus_tools() {
  venv_python -m talkingface.corpus setup >&2
}

ensure_venv() {
  local py="${PYTHON:-python3}"
  "$py" -c 'import sys; assert sys.version_info >= (3, 11)' 2>/dev/null ||
    { say "Python 3.11+ is required (found: $("$py" --version 2>&1))"; return 1; }
  # The dependency list in training/pyproject.toml is the single source; its hash names the install.
  local deps want
  deps="$("$py" - "$REPO_ROOT/training/pyproject.toml" <<'PY'
import sys, tomllib
p = tomllib.load(open(sys.argv[1], "rb"))["project"]
print("\n".join(p["dependencies"] + sum(p.get("optional-dependencies", {}).values(), [])))
PY
)"
  want="$(printf '%s' "$deps" | sha256sum | cut -d' ' -f1)"
  if [ -f "$TALKING_FACE_VENV/.deps-sha256" ] && [ "$(cat "$TALKING_FACE_VENV/.deps-sha256")" = "$want" ]; then return 0; fi
  say "creating the Python venv at $TALKING_FACE_VENV (PyTorch is a large download; this happens once)"
  [ -x "$TALKING_FACE_VENV/bin/python" ] || "$py" -m venv "$TALKING_FACE_VENV"
  local -a reqs
  mapfile -t reqs <<<"$deps"
  "$TALKING_FACE_VENV/bin/python" -m pip install --disable-pip-version-check -q "${reqs[@]}"
  echo "$want" >"$TALKING_FACE_VENV/.deps-sha256"
}

# Run the toolkit's Python with the checkout's sources on the path (no install step to go stale).
venv_python() {
  PYTHONPATH="$REPO_ROOT/training/src${PYTHONPATH:+:$PYTHONPATH}" "$TALKING_FACE_VENV/bin/python" "$@"
}
