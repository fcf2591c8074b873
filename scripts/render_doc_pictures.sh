#!/usr/bin/env bash
# render_doc_pictures.sh — renders the pictures in README.md and docs/ from
# the scenes' own output: runs each scene through the runner (cpu backend)
# and draws its last frame with scripts/render_frames.py (python3-vtk9,
# offscreen under xvfb-run). Rerun it after a change that alters what a
# scene looks like, and commit docs/images/.
#
#   scripts/render_doc_pictures.sh [BUILD_DIR]      (default: build)
set -euo pipefail
build="${1:-build}"
here="$(cd "$(dirname "$0")/.." && pwd)"
python="${PYTHON:-python3}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# scene file, frames, picture name, camera
render() {
  local scene="$1" frames="$2" name="$3" view="$4"
  "$build/apps/sinew/sinew" run "$here/scenes/$scene.json" --backend cpu --frames "$frames" --every "$frames" \
    --quiet --out "$work/$name" > /dev/null
  "$python" "$here/scripts/render_frames.py" "$work/$name" --last --out-dir "$work/png_$name" --size 800 450 \
    --view "$view" > /dev/null
  cp "$work/png_$name"/*.png "$here/docs/images/$name.png"
  echo "wrote docs/images/$name.png"
}

render tissue_sag 120 tissue_sag iso
render grasp_and_cut 90 grasp_and_cut iso
