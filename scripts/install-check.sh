#!/usr/bin/env bash
# Checks that vmpray installs as a command-line tool should, from a built
# build folder (vmpray and its vmpray.1 and vmpray.bash-completion, which the
# build prints after linking):
#   - `cmake --install` into a scratch prefix installs exactly the program,
#     its manual page, its bash completion, README.md and LICENSE; the tree
#     is then moved (installed to A, copied to B, A removed), and B's vmpray,
#     run from an empty folder with a bare environment, renders the default
#     image and prints --help and --version, reading nothing from the build
#     or source folders (its strings name neither; under strace, when it can
#     trace, it opens nothing there);
#   - the page renders with `man --warnings` and no warning, and man finds it;
#   - the completion offers --topology after --to and hypercube after
#     --topology, called as bash calls it, and bash-completion's loader (when
#     installed) finds it under the prefix;
#   - `cpack -G DEB` makes vmpray_VERSION_ARCH.deb, whose control file names
#     the libraries the program links and whose files are the installed ones;
#   - with --apt (as root, vmpray not installed): `apt-get install` of the
#     package, /usr/bin/vmpray --version, then `apt-get remove` again, also
#     when a check in between fails.
# The build folder is only read: the package is made in a scratch folder.
#
# usage: scripts/install-check.sh [BUILD_DIR] [--apt]   (default build/release)
set -euo pipefail

source_dir=$(cd "$(dirname "$0")/.." && pwd)
build="" apt=0
for arg in "$@"; do
  case $arg in
    --apt) apt=1 ;;
    -*) echo "usage: scripts/install-check.sh [BUILD_DIR] [--apt]" >&2; exit 2 ;;
    *) build=$arg ;;
  esac
done
build=$(cd "${build:-$source_dir/build/release}" && pwd)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

fail() {
  echo "install-check: FAILED: $*" >&2
  exit 1
}
say() { echo "install-check: $*"; }

for made in app/vmpray vmpray.1 vmpray.bash-completion CPackConfig.cmake; do
  [[ -f $build/$made ]] || fail "$build/$made is missing: configure and build vmpray there first"
done
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")
[[ -n $version ]] || fail "no CMAKE_PROJECT_VERSION in $build/CMakeCache.txt"

# ---- cmake --install, moved ----
cmake --install "$build" --prefix "$scratch/a" >"$scratch/install.log" || { cat "$scratch/install.log"; fail "cmake --install"; }
cp -a "$scratch/a" "$scratch/b"
rm -rf "$scratch/a"
prefix=$scratch/b
expected="bin/vmpray
share/bash-completion/completions/vmpray
share/doc/vmpray/LICENSE
share/doc/vmpray/README.md
share/man/man1/vmpray.1"
installed=$(cd "$prefix" && find . -type f -o -type l | sed 's|^\./||' | LC_ALL=C sort)
[[ $installed == "$expected" ]] || fail "cmake --install put in the prefix:"$'\n'"$installed"$'\n'"expected:"$'\n'"$expected"
say "cmake --install: $(echo "$installed" | tr '\n' ' ')"

vmpray=$prefix/bin/vmpray
for folder in "$build" "$source_dir"; do
  if grep -a -q -F "$folder" "$vmpray"; then fail "the installed vmpray names $folder"; fi
  if ldd "$vmpray" | grep -q -F "$folder"; then fail "the installed vmpray loads a library from $folder"; fi
done
say "the installed binary names neither $build nor $source_dir, nor loads a library from them"

# ---- the installed program, from an empty folder with a bare environment ----
mkdir "$scratch/run" "$scratch/home"
run() { (cd "$scratch/run" && env -i PATH=/usr/bin:/bin HOME="$scratch/home" "$@"); }
render=("$vmpray" -q)
if strace -f -o /dev/null true 2>/dev/null; then
  run strace -f -q -e trace=open,openat,execve -o "$scratch/opened.txt" "${render[@]}"
  if grep -F -e "\"$build" -e "\"$source_dir" "$scratch/opened.txt" >"$scratch/touched.txt"; then
    cat "$scratch/touched.txt" >&2
    fail "the installed vmpray opened files in the build or source folder"
  fi
  say "default render under strace: no file opened in the build or source folder"
else
  run "${render[@]}"
  say "default render (strace cannot trace here: the files it opens are not checked)"
fi
[[ -s $scratch/run/teapot.png ]] || fail "the default render wrote no teapot.png"
[[ $(head -c 8 "$scratch/run/teapot.png" | od -An -c | tr -d ' ') == '211PNG\r\n032\n' ]] || fail "teapot.png is not a PNG"
if command -v python3 >/dev/null; then python3 "$source_dir/scripts/png-not-blank.py" "$scratch/run/teapot.png"; fi
# Read whole, then searched: grep -q would stop reading at the first line,
# and the rest of the help, written into a closed pipe, would end vmpray by
# SIGPIPE, which pipefail reports as a failure.
help_text=$(run "$vmpray" --help) || fail "--help exits non-zero"
grep -q '^Usage: vmpray' <<<"$help_text" || fail "--help"
version_text=$(run "$vmpray" --version)
[[ $(head -n 1 <<<"$version_text") == "vmpray $version" ]] || fail "--version says '$version_text', not vmpray $version"
grep -q '^compiler: ' <<<"$version_text" || fail "--version names no compiler"
grep -q '^build type: ' <<<"$version_text" || fail "--version names no build type"
say "the installed vmpray renders teapot.png; --help; --version: $(tr '\n' ';' <<<"$version_text")"

# ---- the manual page ----
command -v man >/dev/null || fail "man is not installed (package man-db; scripts/install-deps.sh --dev)"
page=$prefix/share/man/man1/vmpray.1
warnings=$(MANWIDTH=80 man --warnings -l "$page" 2>&1 >/dev/null) || fail "man -l $page failed: $warnings"
[[ -z $warnings ]] || fail "man --warnings -l $page:"$'\n'"$warnings"
[[ $(MANPATH=$prefix/share/man man -w vmpray) == "$page" ]] || fail "man -w vmpray does not find $page"
say "man --warnings -l: no warnings; man finds it under the prefix"

# ---- the completion ----
completion=$prefix/share/bash-completion/completions/vmpray
offers() {  # WORD...: what _vmpray offers for the last word, one a line
  bash --norc --noprofile -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _vmpray
                              printf "%s\n" "${COMPREPLY[@]}"' _ "$completion" "$@"
}
offers vmpray --to | grep -qx -- --topology || fail "the completion does not offer --topology after --to"
offers vmpray --topology "" | grep -qx hypercube || fail "the completion does not offer hypercube after --topology"
loader=/usr/share/bash-completion/bash_completion
if [[ -f $loader ]]; then
  XDG_DATA_DIRS=$prefix/share bash --norc --noprofile -c \
    'source "$1" && __load_completion vmpray && complete -p vmpray' _ "$loader" | grep -q -- '-F _vmpray' ||
    fail "bash-completion's loader does not find the completion under $prefix/share"
  say "completion: --to -> --topology, --topology -> hypercube; bash-completion loads it from the prefix"
else
  say "completion: --to -> --topology, --topology -> hypercube (bash-completion not installed: its loader not tried)"
fi

# ---- the Debian package ----
mkdir "$scratch/package"
cpack -G DEB --config "$build/CPackConfig.cmake" -B "$scratch/package" >"$scratch/cpack.log" 2>&1 ||
  { cat "$scratch/cpack.log"; fail "cpack -G DEB"; }
debs=("$scratch"/package/vmpray_"$version"_*.deb)
[[ -f ${debs[0]} ]] || { cat "$scratch/cpack.log"; fail "cpack made no vmpray_${version}_*.deb"; }
deb=${debs[0]}
control=$(dpkg-deb -I "$deb")
grep -qx ' Package: vmpray' <<<"$control" || fail "the package is not named vmpray"
grep -qx " Version: $version" <<<"$control" || fail "the package's version is not $version"
grep -qx ' Section: science' <<<"$control" || fail "the package's section is not science"
grep -q '^ Maintainer: .' <<<"$control" || fail "the package names no maintainer"
depends=$(sed -n 's/^ Depends: //p' <<<"$control")
for library in libboost-fiber1.74.0 libboost-context1.74.0 libboost-program-options1.74.0 libpng16-16 zlib1g \
  libopenmpi3 libcairo2 fonts-dejavu-core; do
  grep -q "\(^\|, \)$library\( \|,\|$\)" <<<"$depends" || fail "the package's Depends lacks $library: $depends"
done
contents=$(dpkg-deb -c "$deb" | awk '{print $6}')
for file in ./usr/bin/vmpray ./usr/share/man/man1/vmpray.1 ./usr/share/bash-completion/completions/vmpray \
  ./usr/share/doc/vmpray/README.md ./usr/share/doc/vmpray/LICENSE; do
  grep -qx -- "$file" <<<"$contents" || fail "the package lacks $file"
done
say "cpack: $(basename "$deb"), Depends: $depends"

# ---- apt-get install and remove ----
if ((apt)); then
  [[ $(id -u) -eq 0 ]] || fail "--apt installs the package: run as root"
  if dpkg-query -W -f='${Status}' vmpray 2>/dev/null | grep -q 'install ok installed'; then
    fail "a vmpray package is installed already: remove it before --apt"
  fi
  chmod a+rx "$scratch" "$scratch/package"  # apt reads the file as its own user
  trap 'apt-get remove -y -qq vmpray >/dev/null 2>&1 || true; rm -rf "$scratch"' EXIT
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$deb" >"$scratch/apt.log" 2>&1 ||
    { cat "$scratch/apt.log"; fail "apt-get install $deb"; }
  [[ $(/usr/bin/vmpray --version | head -n 1) == "vmpray $version" ]] || fail "/usr/bin/vmpray --version"
  man -w vmpray | grep -q '^/usr/share/man/man1/vmpray\.1' || fail "man does not find the installed page"
  DEBIAN_FRONTEND=noninteractive apt-get remove -y -qq vmpray >"$scratch/apt.log" 2>&1 ||
    { cat "$scratch/apt.log"; fail "apt-get remove vmpray"; }
  [[ ! -e /usr/bin/vmpray ]] || fail "/usr/bin/vmpray is still there after apt-get remove"
  say "apt-get install: /usr/bin/vmpray --version says vmpray $version; apt-get remove: gone again"
fi
say "passed"
