#!/usr/bin/env bash
# Instructions per texel of each summed-area table scheme (msm::gpu::SatBuilder) on lavapipe,
# counted by callgrind: the counts repeat however loaded the machine is (times do not).
#
#   scripts/callgrind-sat.sh [-t MSM_SAT_TIMING] [sizes...]      (default size 512)
#
# Runs `msm_sat_timing --callgrind --repeat 1 SIZES` under valgrind --tool=callgrind
# --instr-atstart=no with LP_NUM_THREADS=0 (llvmpipe dispatches on the submitting thread) and
# VK_ICD_FILENAMES on lavapipe; msm_sat_timing dumps one submission of each scheme alone (after an
# uncounted warm-up). Needs valgrind (scripts/bootstrap.sh installs it).
set -euo pipefail

timing=build/src/gpu/msm_sat_timing
if [[ ${1:-} == -t ]]; then timing=$2; shift 2; fi
[[ $# -gt 0 ]] || set -- 512
command -v valgrind >/dev/null || { echo "callgrind-sat.sh: valgrind is not installed (scripts/bootstrap.sh)" >&2; exit 2; }
[[ -x $timing ]] || { echo "callgrind-sat.sh: no msm_sat_timing at '$timing' (build it, or -t PATH)" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
icd=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
[[ -f $icd ]] && export VK_ICD_FILENAMES=$icd

MESA_SHADER_CACHE_DISABLE=true LP_NUM_THREADS=0 valgrind --tool=callgrind --instr-atstart=no \
  --callgrind-out-file="$out/callgrind.out" "$timing" --callgrind --repeat 1 "$@" >"$out/log" 2>&1 || {
  echo "callgrind-sat.sh: msm_sat_timing --callgrind failed:" >&2
  tail -n 20 "$out/log" >&2
  exit 2
}
# Each dump: "desc: Trigger: Client Request: msm-sat SIZE SCHEME" and "totals: Ir".
for f in "$out"/callgrind.out.*; do
  awk '/^desc: Trigger: Client Request: msm-sat/ { label = $0; sub(/.*msm-sat /, "", label) }
       /^totals:/ { ir = $2 }
       END { if (label != "") print label, ir }' "$f"
done | sort -k1,1n -k2,2n | awk '
  BEGIN {
    name[0] = "rows + columns"; name[1] = "blocks (App. C)"; name[2] = "scan rows + columns"
    name[3] = "subgroup rows + columns"; name[4] = "subgroup rows + subgroup columns"
    printf "%-6s %-34s %14s %10s\n", "size", "scheme", "instructions", "per texel"
  }
  { printf "%-6s %-34s %14d %10.1f\n", $1, name[$2], $3, $3 / ($1 * $1) }'
