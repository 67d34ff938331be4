#!/usr/bin/env bash
# Image-based lighting against the ground truth (issue 15; docs/results.md, "Image-based lighting
# against the ground truth"): for one scene with a "probe", the full-probe truth and the area-light
# truth per light count (msm reference --effect environment [--extracted-lights] --lights N), the
# renders (msm render --lights N -t T), and the MAE of the tone-mapped images (msm compare of
# radiance.png with the render's PNG, background masked):
#   total   = render vs the full-probe truth
#   lights  = area-light truth vs the full-probe truth (the error of the light extraction)
#   shadows = render vs the area-light truth (the error of the shadows and the shading)
# Usage: scripts/ibl-compare.sh SCENE OUT [WIDTH HEIGHT SAMPLES SHADOW_SIZE]   (MSM: the msm binary)
# SAMPLES (default 1024) per pixel for the full probe's truth, a quarter for the area lights' (one
# direction per light each), a sixteenth for 256 lights: at 64 the probe's truth alone is off its
# 1024-sample self by MAE 0.010 on sky_probe, as much as the whole "lights" error.
# Environment (all optional):
#   PROBE=FILE      light the scene with this probe (EXR, cross, "{face}" faces or "sky") instead of its own lighting (--probe
#                   of msm reference and msm render: the scene's probe settings kept, else 32 lights
#                   at 128² per face), any scene (e.g. models)
#   TECHNIQUES=...  the techniques below 256 lights (default mssm6,mssm4,pcss,vssm,cssm16,msm-hamburger-64;
#                   256 lights: msm-hamburger-64 alone, the point-light limit)
#   COUNTS="..."    light counts (default "16 32 64 256")
#   SUB_LIGHTS=M    each light's sub-lights from the cut into M regions (--sub-lights M; the area-light
#                   truth then traces the sub-lights); unset: the scene's
#   SEED=N          seed of the ground truths (default 1)
#   NOISE=1         also the full-probe truth with seed SEED+1, and the MAE between the two (the
#                   truth's own noise, which the other MAEs carry too)
#   ERROR_IMAGES=1  OUT/render-N/T-error.png against the full-probe truth (msm compare --error-image)
set -euo pipefail
scene=$1 out=$2 width=${3:-160} height=${4:-90} samples=${5:-1024} shadow=${6:-256}
msm=${MSM:-build/tools/msm/msm}
techniques_all=${TECHNIQUES:-mssm6,mssm4,pcss,vssm,cssm16,msm-hamburger-64}
counts=${COUNTS:-16 32 64 256}
seed=${SEED:-1}
sub=()
[ -n "${SUB_LIGHTS:-}" ] && sub=(--sub-lights "$SUB_LIGHTS")
mkdir -p "$out"
probe=()
[ -n "${PROBE:-}" ] && probe=(--probe "$PROBE")
size=(--width "$width" --height "$height")
mae() { "$msm" compare --json "$1" "$2" --mask "$out/truth/visibility.exr" --mask-channel background "${@:3}" |
  sed -n 's/.*"mae": \([0-9.e+-]*\).*/\1/p'; }
"$msm" reference --scene "$scene" "${probe[@]}" --effect environment "${size[@]}" --samples "$samples" \
  --seed "$seed" --out "$out/truth" >/dev/null
if [ "${NOISE:-0}" = 1 ]; then
  "$msm" reference --scene "$scene" "${probe[@]}" --effect environment "${size[@]}" --samples "$samples" \
    --seed $((seed + 1)) --out "$out/truth-seed2" >/dev/null
  printf 'truth noise (MAE between seeds %s and %s, %s samples): %.4f\n' "$seed" $((seed + 1)) "$samples" \
    "$(mae "$out/truth/radiance.png" "$out/truth-seed2/radiance.png")"
fi
printf '%-18s %6s %8s %8s %8s\n' technique lights total lights shadows
for n in $counts; do
  "$msm" reference --scene "$scene" "${probe[@]}" --effect environment --extracted-lights --lights "$n" "${sub[@]}" \
    "${size[@]}" \
    --seed "$seed" \
    --samples "$([ "$n" = 256 ] && echo $((samples / 16 > 4 ? samples / 16 : 4)) || echo $((samples / 4 > 4 ? samples / 4 : 4)))" \
    --out "$out/lights-$n" >/dev/null
  lights=$(mae "$out/truth/radiance.png" "$out/lights-$n/radiance.png")
  techniques=$techniques_all
  [ "$n" = 256 ] && techniques="msm-hamburger-64"
  "$msm" render --scene "$scene" "${probe[@]}" --lights "$n" "${sub[@]}" -t "$techniques" "${size[@]}" \
    --shadow-size "$shadow" \
    --device "${MSM_DEVICE:-cpu}" -o "$out/render-$n" >/dev/null 2>&1
  for t in ${techniques//,/ }; do
    error=()
    [ "${ERROR_IMAGES:-0}" = 1 ] && error=(--error-image "$out/render-$n/$t-error.png")
    printf '%-18s %6s %8.4f %8.4f %8.4f\n' "$t" "$n" "$(mae "$out/truth/radiance.png" "$out/render-$n/$t.png" "${error[@]}")" \
      "$lights" "$(mae "$out/lights-$n/radiance.png" "$out/render-$n/$t.png")"
  done
done
