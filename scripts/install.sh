#!/usr/bin/env bash
# Builds the plugin in release mode and installs it under PREFIX (default /usr/local) so an engine can
# find it with pkg-config (`pkg-config --cflags --libs hrts`) or CMake (`find_package(hrts)`):
#   PREFIX/include/hrts.h, PREFIX/lib/libhrts.{so,a}, PREFIX/lib/pkgconfig/hrts.pc,
#   PREFIX/lib/cmake/hrts/hrtsConfig.cmake
set -euo pipefail
cd "$(dirname "$0")/.."
prefix="${1:-/usr/local}"
cargo build --release -p plugin_api
version=$(cargo metadata --no-deps --format-version 1 | sed -n 's/.*"name":"plugin_api","version":"\([^"]*\)".*/\1/p')
install -d "$prefix/include" "$prefix/lib/pkgconfig" "$prefix/lib/cmake/hrts"
install -m 644 plugin_api/include/hrts.h "$prefix/include/"
install -m 755 target/release/libhrts.so "$prefix/lib/"
install -m 644 target/release/libhrts.a "$prefix/lib/"
cat > "$prefix/lib/pkgconfig/hrts.pc" <<PC
prefix=$prefix
libdir=\${prefix}/lib
includedir=\${prefix}/include

Name: hrts
Description: Hybrid ray-traced shadows (deep primitive map) Vulkan plugin
Version: ${version:-0.1.0}
Requires.private: vulkan
Libs: -L\${libdir} -lhrts
Libs.private: -lpthread -ldl -lm
Cflags: -I\${includedir}
PC
cat > "$prefix/lib/cmake/hrts/hrtsConfig.cmake" <<CM
# hrts: imported target hrts::hrts (shared library + header)
add_library(hrts::hrts SHARED IMPORTED)
set_target_properties(hrts::hrts PROPERTIES
  IMPORTED_LOCATION "$prefix/lib/libhrts.so"
  INTERFACE_INCLUDE_DIRECTORIES "$prefix/include")
set(hrts_FOUND TRUE)
CM
echo "installed hrts ${version:-} into $prefix"
