#!/usr/bin/env bash
# Installs, with apt-get, exactly the Debian packages vmpray needs that are
# missing. Idempotent: a second run installs nothing. Run as root.
# --dev adds the developer tools (sanitizer runtime, fuzzer, browser,
# ccache, iproute2 for the cluster check; man-db, bash-completion, dpkg-dev
# and file for the install check and the Debian package's Depends); --ccache
# installs only ccache.
set -euo pipefail
packages=(
  cmake ninja-build g++ pkg-config
  libboost-fiber-dev libboost-context-dev libboost-program-options-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libpng-dev zlib1g-dev
  libopenmpi-dev openmpi-bin
  nlohmann-json3-dev libcairo2-dev fonts-dejavu-core
)
case "${1:-}" in
  --dev) # sanitizers' clang runtime, the fuzzer, the browser checks, ccache, namespaces, the install check
    packages+=(clang-14 libclang-rt-14-dev chromium python3 ccache iproute2 util-linux
               man-db bash-completion dpkg-dev file) ;;
  --ccache) # only the compiler cache every preset uses when installed
    packages=(ccache) ;;
  "") ;;
  *) echo "usage: scripts/install-deps.sh [--dev | --ccache]" >&2; exit 2 ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "install-deps: installing ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
