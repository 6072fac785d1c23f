#!/bin/sh
# Installs Mesa 25's lavapipe, which has VK_KHR_ray_query, from Debian 12's bookworm-backports suite into
# .lavapipe-rt/ of this project, without touching the system's packages, and prints the lines that select it:
#
#     eval "$(scripts/lavapipe-rt.sh)"      # then sunshade (and the tests) use that lavapipe
#
# Idempotent: when it is installed, it only prints the lines (well under a second). The mirror is the one the
# system's own apt sources use for bookworm. On failure it prints the reason on stderr, nothing on stdout, and
# exits 1. See docs/platform.md ("A lavapipe with ray queries").
set -eu
ROOT="$(cd "$(dirname "$0")/.." && pwd)/.lavapipe-rt"
LIB="$ROOT/usr/lib/x86_64-linux-gnu"
ICD="$ROOT/lvp_icd.json"

print_exports() {
    echo "export VK_ICD_FILENAMES='$ICD'"
    echo "export VK_DRIVER_FILES='$ICD'"
    echo "export LD_LIBRARY_PATH='$LIB'\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
}

fail() {
    echo "lavapipe-rt: $*" >&2
    exit 1
}

if [ -f "$ICD" ] && [ -f "$LIB/libvulkan_lvp.so" ]; then
    print_exports
    exit 0
fi
[ "$(uname -m)" = x86_64 ] || fail "only x86_64 is supported (this is $(uname -m))"
command -v apt-get >/dev/null 2>&1 || fail "apt-get is missing (not a Debian-like system)"
command -v dpkg >/dev/null 2>&1 || fail "dpkg is missing"

# The mirror the system uses for Debian bookworm: deb822 sources first, then the one-line format.
mirror=$(awk '
    /^URIs:/ { uris = $2 }
    /^Suites:/ { for (i = 2; i <= NF; i++) if ($i == "bookworm") found = uris }
    /^$/ { uris = "" }
    END { print found }' /etc/apt/sources.list.d/*.sources 2>/dev/null || true)
if [ -z "$mirror" ] && [ -f /etc/apt/sources.list ]; then
    mirror=$(awk '$1 == "deb" && $3 == "bookworm" { print $2; exit }' /etc/apt/sources.list)
fi
[ -n "$mirror" ] || fail "no Debian bookworm mirror found in /etc/apt/sources.list(.d)"

work="$ROOT.tmp"
rm -rf "$work"
mkdir -p "$work/lists/partial" "$work/debs"
keyring=/usr/share/keyrings/debian-archive-keyring.gpg
echo "deb [signed-by=$keyring] $mirror bookworm-backports main" >"$work/sources.list"
apt_opts="-o Dir::Etc::SourceList=$work/sources.list -o Dir::Etc::SourceParts=/dev/null -o Dir::State::Lists=$work/lists -o Debug::NoLocking=1"
# shellcheck disable=SC2086
apt-get $apt_opts -qq update >"$work/update.log" 2>&1 || fail "apt-get update of bookworm-backports failed (see $work/update.log)"
(
    cd "$work/debs"
    # shellcheck disable=SC2086
    apt-get $apt_opts -qq download mesa-vulkan-drivers/bookworm-backports libdrm2/bookworm-backports \
        libdrm-amdgpu1/bookworm-backports
) >"$work/download.log" 2>&1 || fail "downloading mesa-vulkan-drivers from bookworm-backports failed (see $work/download.log)"
version=$(dpkg-deb -f "$work"/debs/mesa-vulkan-drivers_*.deb Version)
rm -rf "$ROOT"
mkdir -p "$ROOT"
for deb in "$work"/debs/*.deb; do
    dpkg -x "$deb" "$ROOT"
done
[ -f "$LIB/libvulkan_lvp.so" ] || fail "the package has no libvulkan_lvp.so"
sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"$LIB/libvulkan_lvp.so\"|" \
    "$ROOT/usr/share/vulkan/icd.d/lvp_icd.json" >"$ICD.tmp"
mv "$ICD.tmp" "$ICD"
rm -rf "$work"
echo "lavapipe-rt: installed mesa-vulkan-drivers $version into $ROOT" >&2
print_exports
