#!/usr/bin/env bash
# Installs what the demo and the tests need on Debian (or Ubuntu), if missing: Mesa's lavapipe (CPU Vulkan),
# the Vulkan loader and validation layers, a C/C++ toolchain (glslang is compiled from source; the C host
# test is built with the system compiler), pkg-config and CMake (the install test consumes the installed
# plugin with both). Idempotent; needs root or sudo only when something is missing.
#
# On Debian 12 (bookworm), Mesa 22.3's lavapipe has no ray tracing, which the ray-tracing-pipeline peer
# (tests/tests/rt_peer.rs) needs: Mesa comes from bookworm-backports (Mesa 25), a suite enabled from the
# machine's own Debian apt source (same mirror and keyring), never from a hard-coded address.
set -euo pipefail

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"

installed() {
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"
}

packages=(mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers g++ gcc make pkg-config cmake)
missing=()
for p in "${packages[@]}"; do
  installed "$p" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Prints "URI<TAB>Signed-By" of the apt source serving `$1` (the release suite itself, not -updates or
# -security): from deb822 .sources files first, then from one-line sources.list entries.
release_source() {
  local suite=$1 f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -e "$f" ] || continue
    # Stanzas are separated by blank lines; a field may continue on lines starting with white space.
    awk -v suite="$suite" '
      function flush() {
        if (types ~ /(^| )deb( |$)/ && (" " suites " ") ~ (" " suite " ") && uris != "" && enabled != "no") {
          split(uris, u, " "); print u[1] "\t" signed; found = 1; exit
        }
        types = suites = uris = signed = field = ""; enabled = "yes"
      }
      BEGIN { enabled = "yes" }
      /^[ \t]*#/ { next }
      /^[ \t]*$/ { flush(); next }
      /^[ \t]/ { if (field == "uris") uris = uris " " $1; next }
      {
        key = tolower($1); sub(/:$/, "", key); value = $0; sub(/^[^:]*:[ \t]*/, "", value)
        field = key
        if (key == "types") types = value
        else if (key == "suites") suites = value
        else if (key == "uris") uris = value
        else if (key == "signed-by") signed = value
        else if (key == "enabled") enabled = tolower(value)
      }
      END { if (!found) flush() }
    ' "$f" | head -n 1 | grep . && return 0
  done
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -e "$f" ] || continue
    # deb [opt=value ...] URI suite components...
    awk -v suite="$suite" '
      $1 != "deb" { next }
      {
        i = 2; signed = ""
        if ($2 ~ /^\[/) {
          while (i <= NF) {
            opt = $i; gsub(/[\[\]]/, "", opt)
            if (opt ~ /^signed-by=/) { signed = opt; sub(/^signed-by=/, "", signed) }
            if ($i ~ /\]$/) { i++; break }
            i++
          }
        }
        if ($(i + 1) == suite) { print $i "\t" signed; exit }
      }
    ' "$f" | head -n 1 | grep . && return 0
  done
  return 1
}

# Mesa >= 25 (lavapipe with VK_KHR_ray_tracing_pipeline) from bookworm-backports, on Debian 12 only.
mesa_from_backports() {
  local id codename version source uri signed list
  id=$(. /etc/os-release && echo "${ID:-}")
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
  [ "$id" = debian ] && [ "$codename" = bookworm ] || return 0
  version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  if [ -n "$version" ] && dpkg --compare-versions "$version" ge 25; then
    return 0
  fi
  list=/etc/apt/sources.list.d/bookworm-backports.sources
  if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    if ! source=$(release_source bookworm); then
      echo "error: no apt source for bookworm found; cannot derive bookworm-backports for Mesa 25" >&2
      exit 1
    fi
    uri=${source%%$'\t'*}
    signed=${source#*$'\t'}
    echo "enabling bookworm-backports from $uri (for Mesa 25: lavapipe with ray tracing)"
    {
      echo "Types: deb"
      echo "URIs: $uri"
      echo "Suites: bookworm-backports"
      echo "Components: main"
      [ -z "$signed" ] || echo "Signed-By: $signed"
    } | $sudo tee "$list" >/dev/null
  fi
  $sudo apt-get update -qq
  echo "installing mesa-vulkan-drivers from bookworm-backports"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    -t bookworm-backports mesa-vulkan-drivers
  version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers)
  if ! dpkg --compare-versions "$version" ge 25; then
    echo "error: bookworm-backports gave mesa-vulkan-drivers $version, not Mesa 25 or later" >&2
    exit 1
  fi
}
mesa_from_backports

if ! command -v cargo >/dev/null; then
  echo "error: Rust is required (cargo not found); install it with rustup (https://rustup.rs)" >&2
  exit 1
fi
