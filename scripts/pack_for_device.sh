#!/usr/bin/env bash
# Packs the benchmark and test executables of a build, with the shared
# libraries they need beyond the C runtime (TBB, Google Benchmark/Test, the
# OpenCL ICD loader, the Vulkan loader), into one folder that can be copied
# to a bare GPU machine and run there by scripts/measure_gpu.sh.
#   scripts/pack_for_device.sh [BUILD_DIR] [OUT_DIR]   (defaults: build, .gpu)
# The GPU machine's own driver supplies the OpenCL ICD and Vulkan ICD files.
set -euo pipefail
build=${1:-build}
out=${2:-.gpu}
programs=(benchmarks/bench_cube benchmarks/bench_dispatch benchmarks/error_vs_time tests/test_backends)
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
for p in "${programs[@]}"; do
  [ -x "$build/$p" ] || { echo "pack_for_device: $build/$p is missing (build it first)" >&2; exit 1; }
  cp "$build/$p" "$out/bin/"
  # Every library ldd resolves, except the C runtime the GPU machine has.
  ldd "$build/$p" | awk '$3 ~ /^\// {print $3}' | while read -r lib; do
    case "$(basename "$lib")" in
      libc.so.*|libm.so.*|libdl.so.*|libpthread.so.*|librt.so.*|ld-linux*) ;;
      *) cp -L -n "$lib" "$out/lib/" ;;
    esac
  done
done
cp scripts/measure_gpu.sh "$out/"
echo "pack_for_device: $(ls "$out/bin" | wc -l) programs and $(ls "$out/lib" | wc -l) libraries in $out ($(du -sh "$out" | cut -f1))"
