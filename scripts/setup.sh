#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (root or sudo):
#   scripts/setup.sh run    install what is missing, build (Release), start remeshd
#   scripts/setup.sh test   install what is missing (test tools too), build, run the whole test suite
#   scripts/setup.sh deps [--test]   only install;   scripts/setup.sh build   only build
# Idempotent: installs nothing that is already there, rebuilds only what changed.
# Environment: REMESH_BUILD_DIR (default ./build), REMESH_JOBS (default: cores),
# REMESH_CMAKE_ARGS (extra options for the first configure).
#   scripts/setup.sh deps --runtime   only what a built remeshd needs to run (Dockerfile)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${REMESH_BUILD_DIR:-$ROOT/build}
JOBS=${REMESH_JOBS:-$(nproc)}

# What building and running needs, and what only the tests need.
BUILD_PACKAGES=(g++ cmake ninja-build pkg-config ca-certificates
  libcpp-httplib-dev zlib1g-dev libbrotli-dev nlohmann-json3-dev libopenmesh-dev libnanoflann-dev libtinygltf-dev catch2)
TEST_PACKAGES=(chromium curl)
# What the built remeshd needs at run time (the Dockerfile's final stage).
RUNTIME_PACKAGES=(libopenmesh1 libtinygltf2d libcpp-httplib0.11 zlib1g libbrotli1 curl ca-certificates)

log() { printf '[setup] %s\n' "$*" >&2; }

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    log "need root (or sudo) to run: $*"; exit 1; fi
}

missing_packages() {
  local p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || echo "$p"
  done
}

install_packages() {
  local missing
  missing=$(missing_packages "$@")
  # Node.js: any machine-wide node >= 18 with npm will do; else Debian's.
  if [ -z "${NO_NODE:-}" ] && { ! command -v npm >/dev/null || ! command -v node >/dev/null; }; then
    missing="$missing nodejs npm"
  fi
  if [ -n "${missing// /}" ]; then
    log "installing:$(echo $missing | tr '\n' ' ')"
    as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    # shellcheck disable=SC2086
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing >/dev/null
  fi
}

web_packages() {
  # Front-end packages, pinned by web/package-lock.json; reinstalled only when the lockfile changed.
  [ -f "$ROOT/web/package-lock.json" ] || return 0
  local stamp="$ROOT/web/node_modules/.lock-stamp"
  local sum; sum=$(sha256sum "$ROOT/web/package-lock.json" | cut -d' ' -f1)
  if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$sum" ]; then
    log "installing front-end packages (npm ci)"
    (cd "$ROOT/web" && npm ci --no-audit --no-fund --loglevel=error)
    echo "$sum" > "$stamp"
  fi
}

deps() {
  case "${1:-}" in
    --test) install_packages "${BUILD_PACKAGES[@]}" "${TEST_PACKAGES[@]}" ;;
    --runtime) NO_NODE=1 install_packages "${RUNTIME_PACKAGES[@]}"; return 0 ;;
    *) install_packages "${BUILD_PACKAGES[@]}" ;;
  esac
  web_packages
}

build() {
  if [ ! -f "$BUILD/CMakeCache.txt" ]; then
    # shellcheck disable=SC2086
    cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release ${REMESH_CMAKE_ARGS:-} >/dev/null
  fi
  cmake --build "$BUILD" -j "$JOBS"
}

run() {
  if [ -x "$BUILD/bin/remeshd" ]; then
    log "remeshd on http://${REMESHD_HOST:-127.0.0.1}:${REMESHD_PORT:-8080}/ (Ctrl-C stops it)"
    exec "$BUILD/bin/remeshd" "$@"
  fi
  "$BUILD/bin/remesh" info "$ROOT/tests/data/tetra_sphere.obj"
}

cmd=${1:-run}; shift || true
case "$cmd" in
  deps) deps "$@" ;;
  build) deps; build ;;
  run) deps; build; run "$@" ;;
  test) deps --test; build; cd "$BUILD" && ctest --output-on-failure -j "$JOBS" "$@" ;;
  *) echo "usage: $0 run|test|deps [--test]|build" >&2; exit 2 ;;
esac
