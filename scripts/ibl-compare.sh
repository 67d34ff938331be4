#!/usr/bin/env bash
# Image-based lighting against the ground truth (issue 15; docs/results.md, "Image-based lighting
# against the ground truth"): for one scene with a "probe", the full-probe truth and the area-light
# truth per light count (msm reference --effect environment [--probe-lights] --lights N), the
# renders (msm render --lights N -t T), and the MAE of the tone-mapped images (msm compare of
# radiance.png with the render's PNG, background masked):
#   total   = render vs the full-probe truth
#   lights  = area-light truth vs the full-probe truth (the error of the light extraction)
#   shadows = render vs the area-light truth (the error of the shadows and the shading)
# Usage: scripts/ibl-compare.sh SCENE OUT [WIDTH HEIGHT SAMPLES SHADOW_SIZE]   (MSM: the msm binary)
# SAMPLES (default 1024) per pixel for the full probe's truth, a quarter for the area lights' (one
# direction per light each), a sixteenth for 256 lights: at 64 the probe's truth alone is off its
# 1024-sample self by MAE 0.010 on sky_probe, as much as the whole "lights" error.
set -euo pipefail
scene=$1 out=$2 width=${3:-160} height=${4:-90} samples=${5:-1024} shadow=${6:-256}
msm=${MSM:-build/tools/msm/msm}
mkdir -p "$out"
size=(--width "$width" --height "$height")
mae() { "$msm" compare --json "$1" "$2" --mask "$out/truth/visibility.exr" --mask-channel background |
  sed -n 's/.*"mae": \([0-9.e+-]*\).*/\1/p'; }
"$msm" reference --scene "$scene" --effect environment "${size[@]}" --samples "$samples" --out "$out/truth" >/dev/null
printf '%-18s %6s %8s %8s %8s\n' technique lights total lights shadows
for n in 16 32 64 256; do
  "$msm" reference --scene "$scene" --effect environment --probe-lights --lights "$n" "${size[@]}" \
    --samples "$([ "$n" = 256 ] && echo $((samples / 16 > 4 ? samples / 16 : 4)) || echo $((samples / 4 > 4 ? samples / 4 : 4)))" \
    --out "$out/lights-$n" >/dev/null
  lights=$(mae "$out/truth/radiance.png" "$out/lights-$n/radiance.png")
  techniques="mssm6,mssm4,pcss,msm-hamburger-64"
  [ "$n" = 256 ] && techniques="msm-hamburger-64"
  "$msm" render --scene "$scene" --lights "$n" -t "$techniques" "${size[@]}" --shadow-size "$shadow" \
    --device "${MSM_DEVICE:-cpu}" -o "$out/render-$n" >/dev/null 2>&1
  for t in ${techniques//,/ }; do
    printf '%-18s %6s %8.4f %8.4f %8.4f\n' "$t" "$n" "$(mae "$out/truth/radiance.png" "$out/render-$n/$t.png")" \
      "$lights" "$(mae "$out/lights-$n/radiance.png" "$out/render-$n/$t.png")"
  done
done
