#!/usr/bin/env bash
# Packs what the GPU measurement suite runs — the runner, the example
# scenes, the benchmarks and the test programs that hold the backends'
# agreement tests — stripped, with the shared libraries they need beyond the
# C runtime (TBB, OpenVDB, Google Benchmark/Test, the OpenCL ICD loader, the
# Vulkan loader), into one compressed archive that can be copied to a bare GPU
# machine and run there by scripts/measure_gpu.sh.
#   scripts/pack_for_device.sh [BUILD_DIR] [OUT_DIR]   (defaults: build, .gpu)
# Build the programs first:
#   cmake --build build --target sinew_runner bench_cube bench_dispatch organ_step error_vs_time \
#     bench_mesh_contacts bench_retraction bleeding_organ bench_contact_coloring organ_contact retraction bleeding_kidney suturing cholecystectomy bleeding bone_burr haptic_drag \
#     test_backends test_xpbd test_collision test_fluid test_tissue test_topology test_robustness
# The GPU machine's own driver supplies the OpenCL ICD and Vulkan ICD files;
# the meshes travel packed in the repository's data/ and measure_gpu.sh unpacks
# them where the programs were built to look (the build's SINEW_DATA_DIR).
# Why compressed: what travels to the device machine is capped (64 MiB with the
# working tree), and OpenVDB alone is 55 MB.
set -euo pipefail
build=${1:-build}
out=${2:-.gpu}
programs=(apps/sinew/sinew
          benchmarks/bench_cube benchmarks/bench_dispatch benchmarks/organ_step benchmarks/error_vs_time
          benchmarks/bench_mesh_contacts benchmarks/bench_retraction benchmarks/bleeding_organ benchmarks/bench_contact_coloring
          examples/organ_contact examples/retraction examples/bleeding_kidney examples/suturing examples/cholecystectomy examples/bleeding examples/bone_burr
          examples/haptic_drag
          tests/test_backends tests/test_xpbd tests/test_collision tests/test_fluid tests/test_tissue
          tests/test_topology tests/test_robustness)
data_dir=$(sed -n 's/^SINEW_DATA_DIR:PATH=//p' "$build/CMakeCache.txt")
[ -n "$data_dir" ] || { echo "pack_for_device: no SINEW_DATA_DIR in $build/CMakeCache.txt" >&2; exit 1; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib"
for p in "${programs[@]}"; do
  [ -x "$build/$p" ] || { echo "pack_for_device: $build/$p is missing (build it first, see the top of this script)" >&2; exit 1; }
  strip --strip-unneeded -o "$stage/bin/$(basename "$p")" "$build/$p"
  # Every library ldd resolves, except the C runtime the GPU machine has.
  ldd "$build/$p" | awk '$3 ~ /^\// {print $3}' | while read -r lib; do
    case "$(basename "$lib")" in
      libc.so.*|libm.so.*|libdl.so.*|libpthread.so.*|librt.so.*|ld-linux*) ;;
      *) [ -e "$stage/lib/$(basename "$lib")" ] || strip --strip-unneeded -o "$stage/lib/$(basename "$lib")" "$lib" ;;
    esac
  done
done
rm -rf "$out"
mkdir -p "$out"
tar -C "$stage" -cf - bin lib | xz -T2 -6 > "$out/payload.tar.xz"
echo "$data_dir" > "$out/data_dir.txt"
cp scripts/measure_gpu.sh "$out/"
echo "pack_for_device: ${#programs[@]} programs and $(ls "$stage/lib" | wc -l) libraries in $out/payload.tar.xz ($(du -h "$out/payload.tar.xz" | cut -f1))"
