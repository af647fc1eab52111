#!/usr/bin/env bash
# Set up what the demo needs (npm packages) and serve it with the shipped model.
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
ensure_node_modules
cd "$REPO_ROOT"
say "building the app"
npm run --silent build
PORT="${PORT:-4173}"
say "serving the demo at http://localhost:$PORT/  (Ctrl-C to stop)"
exec npx vite preview --port "$PORT" --strictPort
