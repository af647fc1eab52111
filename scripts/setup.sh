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
  command -v npm >/dev/null || { say "Node.js 20.19+ or 22.12+ with npm is required (https://nodejs.org)"; return 1; }
  # Vite 8 needs ^20.19.0 || >=22.12.0: say so here rather than fail later inside the build.
  node -e 'const [a, b] = process.versions.node.split(".").map(Number); process.exit((a === 20 && b >= 19) || (a === 22 && b >= 12) || a > 22 ? 0 : 1)' ||
    { say "Node.js 20.19+ or 22.12+ is required (found: $(node --version))"; return 1; }
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

# uv (pinned in scripts/uv-requirements.txt by version and hash) resolves nothing at setup time: it installs
# exactly what training/uv.lock lists, every transitive package with its version and hash.
UV_VERSION="$(sed -n 's/^uv==\([0-9.]*\).*/\1/p' "$REPO_ROOT/scripts/uv-requirements.txt")"
UV_HOME="${TALKING_FACE_UV_HOME:-$HOME/.cache/talking-face/uv}"

# training/pyproject.toml: requires-python >=3.11,<3.13 (what the lock was resolved for).
ensure_python() {
  local py="${PYTHON:-python3}"
  "$py" -c 'import sys; assert (3, 11) <= sys.version_info[:2] <= (3, 12)' 2>/dev/null ||
    { say "Python 3.11 or 3.12 is required (found: $("$py" --version 2>&1); another one can be named with PYTHON=...)"; return 1; }
}

ensure_uv() {
  if command -v uv >/dev/null && [ "$(uv --version | cut -d' ' -f2)" = "$UV_VERSION" ]; then UV=uv; return 0; fi
  UV="$UV_HOME/bin/uv"
  if [ -x "$UV" ] && [ "$("$UV" --version | cut -d' ' -f2)" = "$UV_VERSION" ]; then return 0; fi
  local py="${PYTHON:-python3}"
  ensure_python || return 1
  # A venv needs ensurepip, which Debian and Ubuntu ship apart (python3.X-venv).
  if ! "$py" -c 'import ensurepip' 2>/dev/null; then
    local venv_pkg
    venv_pkg="python$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])')-venv"
    if command -v dpkg >/dev/null; then ensure_apt "$venv_pkg" || return 1
    else say "$py cannot make a virtual environment (no ensurepip): install its venv module ($venv_pkg on Debian)"; return 1; fi
  fi
  say "installing uv $UV_VERSION into $UV_HOME (hash-checked)"
  rm -rf "$UV_HOME"
  "$py" -m venv "$UV_HOME" || { say "could not make a virtual environment for uv at $UV_HOME"; return 1; }
  "$UV_HOME/bin/python" -m pip install --disable-pip-version-check -q --require-hashes \
    -r "$REPO_ROOT/scripts/uv-requirements.txt" || { say "could not install uv $UV_VERSION with pip"; return 1; }
}

ensure_venv() {
  # The venv is named by the lock's hash: a changed lock (or pyproject.toml) rebuilds it.
  local want
  want="$(cat "$REPO_ROOT/training/uv.lock" "$REPO_ROOT/training/pyproject.toml" | sha256sum | cut -d' ' -f1)"
  if [ -f "$TALKING_FACE_VENV/.lock-sha256" ] && [ "$(cat "$TALKING_FACE_VENV/.lock-sha256")" = "$want" ]; then return 0; fi
  ensure_python || return 1
  ensure_uv || return 1
  say "syncing the Python venv at $TALKING_FACE_VENV with training/uv.lock (PyTorch is a large download the first time)"
  rm -f "$TALKING_FACE_VENV/.lock-sha256"
  # --locked: fail rather than re-resolve if the lock no longer matches pyproject.toml.
  # --no-install-project: the toolkit runs from the checkout's sources (venv_python), so nothing goes stale.
  (cd "$REPO_ROOT/training" && UV_PROJECT_ENVIRONMENT="$TALKING_FACE_VENV" "$UV" sync --locked --extra test \
    --no-install-project --python "${PYTHON:-python3}" --quiet)
  echo "$want" >"$TALKING_FACE_VENV/.lock-sha256"
}

# Run the toolkit's Python with the checkout's sources on the path (no install step to go stale).
venv_python() {
  PYTHONPATH="$REPO_ROOT/training/src${PYTHONPATH:+:$PYTHONPATH}" "$TALKING_FACE_VENV/bin/python" "$@"
}
