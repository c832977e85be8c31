#!/usr/bin/env bash
# Installs the build into a scratch prefix, then builds a consumer with find_package(rsmooth) and
# another with pkg-config, and runs both.
set -euo pipefail
build_dir=$1
source_dir=$(cd "$2" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$source_dir/tests/package" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer"
libdir=$(dirname "$(find "$work/prefix" -name rsmooth.pc | head -1)")
export PKG_CONFIG_PATH="$libdir"
# rsmooth_io comes before rsmooth, which it uses, for static linking.
cc -std=c11 "$source_dir/tests/package/consumer.c" -o "$work/consumer_pc" \
  $(pkg-config --cflags rsmooth) $(pkg-config --libs-only-L rsmooth) -lrsmooth_io \
  $(pkg-config --libs --static rsmooth)
"$work/consumer_pc"
echo "installed package: find_package and pkg-config consumers built and ran"
