#!/usr/bin/env bash
# Set up what the demo needs (npm packages) and serve it with the shipped model (PORT=N: on port N, default 4173).
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
PORT="${PORT:-4173}"
# A port in use (another demo?) fails now, not after a build that would replace the files that demo serves.
if (exec 3<>"/dev/tcp/localhost/$PORT") 2>/dev/null; then
  echo "demo: port $PORT is in use (another demo running?): stop it, or choose another: PORT=4174 npm run demo" >&2
  exit 1
fi
ensure_node_modules
cd "$REPO_ROOT"
say "building the app"
npm run --silent build
say "serving the demo at http://localhost:$PORT/  (Ctrl-C to stop)"
exec npx vite preview --port "$PORT" --strictPort
