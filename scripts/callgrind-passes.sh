#!/usr/bin/env bash
# Instructions executed per pass of the renderer's frames on lavapipe, counted by callgrind: the
# counts repeat exactly however loaded the machine is, so ratios between passes (and before/after
# a change) hold where times do not. Timing stays with `msm bench`.
#
#   scripts/callgrind-passes.sh [-m MSM] [-o DIR] [msm bench options...]
#   scripts/callgrind-passes.sh --techniques msm-hamburger-64 --shadow-sizes 1024 --resolutions 640x360
#
# It runs `msm bench --callgrind` under valgrind --tool=callgrind --instr-atstart=no with
# LP_NUM_THREADS=0 (llvmpipe rasterizes and dispatches on the submitting thread: no thread pool
# in the counts) and VK_ICD_FILENAMES on lavapipe. msm submits every prefix of each frame alone
# (the first k passes, k = 0 .. n), callgrind dumps the instructions of each submission, and this
# script prints pass k as the difference of prefixes k and k - 1, in total and per unit: per
# pixel for `shading` and `surfaces`, per shadow-map texel (and light) for every other pass.
# Defaults: MSM = build/tools/msm/msm, DIR = a temporary directory (kept with -o). Needs valgrind
# (scripts/bootstrap.sh installs it). A 1024² MSM-64 frame takes about a minute on this machine.
set -euo pipefail
source "$(dirname "$0")/lib/callgrind.sh"

msm=build/tools/msm/msm
out=
while [[ $# -gt 0 ]]; do
  case "$1" in
  -m) msm=$2; shift 2 ;;
  -o) out=$2; shift 2 ;;
  -h | --help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) break ;;
  esac
done
[[ -x $msm ]] || { echo "callgrind-passes.sh: no msm at '$msm' (build it, or -m PATH)" >&2; exit 2; }
if [[ -z $out ]]; then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
else
  mkdir -p "$out"
fi
callgrind_run callgrind-passes.sh "$out" "$msm" bench --callgrind "$@"
# Each dump's trigger: "msm-prefix TECH WxH SIZE K PASS".
callgrind_totals "$out" msm-prefix | sort -k1,1 -k2,2 -k3,3n -k4,4n | awk '
  BEGIN { printf "%-26s %-10s %6s %-16s %14s %10s\n", "technique", "image", "map", "pass", "instructions", "per unit" }
  {
    key = $1 " " $2 " " $3
    if ($4 == 0) { prev = $6; next }
    if (key != last_key) last_key = key
    split($2, wh, "x")
    d = $6 - prev; prev = $6
    unit = ($5 == "shading" || $5 == "surfaces") ? wh[1] * wh[2] : $3 * $3
    printf "%-26s %-10s %6d %-16s %14.0f %10.1f\n", $1, $2, $3, $5, d, d / unit
  }'
