#!/usr/bin/env bash
# Builds the plugin in release mode and installs it under PREFIX (default /usr/local) so an engine can
# find it with pkg-config (`pkg-config --cflags --libs hrts`, add `--static` for libhrts.a) or CMake
# (`find_package(hrts CONFIG)`: targets hrts::hrts for libhrts.so, hrts::hrts_static for libhrts.a):
#   PREFIX/include/hrts.h, PREFIX/lib/libhrts.{so,a}, PREFIX/lib/pkgconfig/hrts.pc,
#   PREFIX/lib/cmake/hrts/hrtsConfig.cmake, PREFIX/lib/cmake/hrts/hrtsConfigVersion.cmake
# HRTS_PROFILE picks another cargo profile (`dev` installs target/debug) and cargo's CARGO_TARGET_DIR is
# honoured, so a test can install the build it already made (cargo then finds nothing to rebuild).
set -euo pipefail

prefix="${1:-/usr/local}"
install -d "$prefix"
prefix="$(cd "$prefix" && pwd)" # absolute, as given relative to the caller's folder
cd "$(dirname "$0")/.."

profile="${HRTS_PROFILE:-release}"
case "$profile" in
  dev | test) folder=debug ;;
  release | bench) folder=release ;;
  *) folder="$profile" ;;
esac
cargo="${CARGO:-cargo}"

# What `cargo rustc -p hrts-capi --crate-type staticlib -- --print native-static-libs` prints: the system
# libraries that Rust's std and the dependencies use (the Vulkan loader is opened with dlopen at run time).
# glslang is only a build dependency (the shaders are compiled into the library), so libhrts.a holds no
# C++ code and needs no -lstdc++.
static_libs=(dl gcc_s util rt pthread m dl c)

"$cargo" build --profile "$profile" -p hrts-capi
metadata="$("$cargo" metadata --no-deps --format-version 1)"
version="$(sed -n 's/.*"name":"hrts","version":"\([^"]*\)".*/\1/p' <<<"$metadata")"
target_dir="$(sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p' <<<"$metadata")"
if [[ -z "$version" || -z "$target_dir" ]]; then
  echo "error: cannot read hrts's version and the target folder from cargo metadata" >&2
  exit 1
fi
build="$target_dir/$folder"
major="${version%%.*}"
major="$((10#$major))"
pointer_size="$(($(getconf LONG_BIT) / 8))"

install -d "$prefix/include" "$prefix/lib/pkgconfig" "$prefix/lib/cmake/hrts"
install -m 644 hrts/include/hrts.h "$prefix/include/"
install -m 755 "$build/libhrts.so" "$prefix/lib/"
install -m 644 "$build/libhrts.a" "$prefix/lib/"

pc_libs="$(printf -- '-l%s ' "${static_libs[@]}")"
cat >"$prefix/lib/pkgconfig/hrts.pc" <<PC
prefix=$prefix
libdir=\${prefix}/lib
includedir=\${prefix}/include

Name: hrts
Description: Hybrid ray-traced shadows (deep primitive map) Vulkan plugin
Version: $version
Requires.private: vulkan
Libs: -L\${libdir} -lhrts
Libs.private: ${pc_libs% }
Cflags: -I\${includedir}
PC

cmake_libs="$(
  IFS=';'
  echo "${static_libs[*]}"
)"
cat >"$prefix/lib/cmake/hrts/hrtsConfig.cmake" <<CM
# hrts $version: imported targets hrts::hrts (libhrts.so) and hrts::hrts_static (libhrts.a with the
# system libraries it needs), both with the header hrts.h. Relocatable: paths are relative to this file.
get_filename_component(_hrts_prefix "\${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)
foreach(_hrts_file include/hrts.h lib/libhrts.so lib/libhrts.a)
  if(NOT EXISTS "\${_hrts_prefix}/\${_hrts_file}")
    set(hrts_FOUND FALSE)
    set(hrts_NOT_FOUND_MESSAGE "\${_hrts_prefix}/\${_hrts_file} is missing")
    return()
  endif()
endforeach()
if(NOT TARGET hrts::hrts)
  add_library(hrts::hrts SHARED IMPORTED)
  set_target_properties(hrts::hrts PROPERTIES
    IMPORTED_LOCATION "\${_hrts_prefix}/lib/libhrts.so"
    IMPORTED_NO_SONAME TRUE
    INTERFACE_INCLUDE_DIRECTORIES "\${_hrts_prefix}/include")
endif()
if(NOT TARGET hrts::hrts_static)
  add_library(hrts::hrts_static STATIC IMPORTED)
  set_target_properties(hrts::hrts_static PROPERTIES
    IMPORTED_LOCATION "\${_hrts_prefix}/lib/libhrts.a"
    IMPORTED_LINK_INTERFACE_LANGUAGES C
    INTERFACE_INCLUDE_DIRECTORIES "\${_hrts_prefix}/include"
    INTERFACE_LINK_LIBRARIES "$cmake_libs")
endif()
unset(_hrts_file)
unset(_hrts_prefix)
CM

# CMake's SameMajorVersion convention (as write_basic_package_version_file writes it): compatible when the
# requested major version is this one and the requested version is not newer; ranges must lie in it.
cat >"$prefix/lib/cmake/hrts/hrtsConfigVersion.cmake" <<CM
set(PACKAGE_VERSION "$version")
if(PACKAGE_VERSION VERSION_LESS PACKAGE_FIND_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
elseif(PACKAGE_FIND_VERSION_RANGE)
  if(PACKAGE_FIND_VERSION_MIN_MAJOR STREQUAL "$major"
      AND ((PACKAGE_FIND_VERSION_RANGE_MAX STREQUAL "INCLUDE"
            AND PACKAGE_FIND_VERSION_MAX_MAJOR STREQUAL "$major"
            AND PACKAGE_VERSION VERSION_LESS_EQUAL PACKAGE_FIND_VERSION_MAX)
        OR (PACKAGE_FIND_VERSION_RANGE_MAX STREQUAL "EXCLUDE"
            AND PACKAGE_FIND_VERSION_MAX VERSION_LESS_EQUAL "$((major + 1))"
            AND PACKAGE_VERSION VERSION_LESS PACKAGE_FIND_VERSION_MAX)))
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
  else()
    set(PACKAGE_VERSION_COMPATIBLE FALSE)
  endif()
else()
  if(PACKAGE_FIND_VERSION_MAJOR STREQUAL "$major")
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
  else()
    set(PACKAGE_VERSION_COMPATIBLE FALSE)
  endif()
  if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
    set(PACKAGE_VERSION_EXACT TRUE)
  endif()
endif()
# A $((pointer_size * 8))-bit library: unsuitable for a project of another pointer size.
if(NOT "\${CMAKE_SIZEOF_VOID_P}" STREQUAL "" AND NOT "\${CMAKE_SIZEOF_VOID_P}" STREQUAL "$pointer_size")
  set(PACKAGE_VERSION "\${PACKAGE_VERSION} ($((pointer_size * 8))bit)")
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
CM

echo "installed hrts $version ($profile build) into $prefix"
