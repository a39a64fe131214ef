#!/usr/bin/env bash
# Installs what the demo and the tests need on Debian (or Ubuntu), if missing: Mesa's lavapipe (CPU Vulkan),
# the Vulkan loader and validation layers, a C/C++ toolchain (glslang is compiled from source; the C host
# test is built with the system compiler), pkg-config and CMake (the install test consumes the installed
# plugin with both). Idempotent; needs root or sudo only when something is missing.
set -euo pipefail

packages=(mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers g++ gcc make pkg-config cmake)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "installing: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
if ! command -v cargo >/dev/null; then
  echo "error: Rust is required (cargo not found); install it with rustup (https://rustup.rs)" >&2
  exit 1
fi
