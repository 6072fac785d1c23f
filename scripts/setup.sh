#!/bin/sh
# Installs the system packages sunshade needs, if any are missing. Idempotent; costs well under a second when
# everything is present. Uses apt-get as root, or through sudo; otherwise stops and names the packages.
#
#   build:   libshaderc-dev glslang-dev spirv-tools   (static shaderc + glslang + SPIRV-Tools archives)
#   run:     libvulkan1 mesa-vulkan-drivers           (the Vulkan loader and lavapipe, Mesa's CPU device)
#   tests:   vulkan-validationlayers                  (every GPU test runs with VK_LAYER_KHRONOS_validation)
#   tools:   vulkan-tools                             (vulkaninfo, for diagnosing a machine)
set -eu

PACKAGES="libshaderc-dev glslang-dev spirv-tools libvulkan1 mesa-vulkan-drivers vulkan-validationlayers vulkan-tools"

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo is not on PATH; install Rust 1.88 or newer (https://rustup.rs) and run this again" >&2
    exit 1
fi

if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "setup: this is not a Debian-like system; install the equivalents of: $PACKAGES" >&2
    exit 1
fi

missing=""
for p in $PACKAGES; do
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    case "$status" in
        *"install ok installed"*) ;;
        *) missing="$missing $p" ;;
    esac
done
[ -z "$missing" ] && exit 0

echo "setup: installing missing packages:$missing" >&2
if [ "$(id -u)" = 0 ]; then
    SUDO=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    SUDO="sudo"
else
    echo "setup: cannot install packages (not root, and no password-less sudo). Please run:" >&2
    echo "  sudo apt-get update && sudo apt-get install -y --no-install-recommends$missing" >&2
    exit 1
fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
echo "setup: done" >&2
