#!/usr/bin/env bash
# Instructions per texel of each summed-area table scheme (msm::gpu::SatBuilder) on lavapipe,
# counted by callgrind: the counts repeat however loaded the machine is (times do not).
#
#   scripts/callgrind-sat.sh [-t MSM_SAT_TIMING] [sizes...]      (default size 512)
#
# Runs `msm_sat_timing --callgrind --repeat 1 SIZES` under valgrind --tool=callgrind
# --instr-atstart=no with LP_NUM_THREADS=0 (llvmpipe dispatches on the submitting thread) and
# VK_ICD_FILENAMES on lavapipe; msm_sat_timing dumps one submission of each scheme alone (after an
# uncounted warm-up), each copy shader of src/gpu/sat_copy.h alike, and one two-thread CPU copy (the
# bound). Needs valgrind (scripts/bootstrap.sh installs it).
set -euo pipefail
source "$(dirname "$0")/lib/callgrind.sh"

timing=build/src/gpu/msm_sat_timing
if [[ ${1:-} == -t ]]; then timing=$2; shift 2; fi
[[ $# -gt 0 ]] || set -- 512
[[ -x $timing ]] || { echo "callgrind-sat.sh: no msm_sat_timing at '$timing' (build it, or -t PATH)" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
callgrind_run callgrind-sat.sh "$out" "$timing" --callgrind --repeat 1 "$@"
# Each dump's trigger: "msm-sat SIZE SCHEME".
callgrind_totals "$out" msm-sat | sort -k1,1n -k2,2n | awk '
  BEGIN {
    name[0] = "rows + columns"; name[1] = "blocks (App. C)"; name[2] = "scan rows + columns"
    name[3] = "subgroup rows + columns"; name[4] = "subgroup rows + subgroup columns"
    name[10] = "copy shader: image, texel"; name[11] = "copy shader: image, row"
    name[12] = "copy shader: image, column"; name[13] = "copy shader: texelFetch -> image, row"
    name[14] = "copy shader: buffer, texel"; name[15] = "copy shader: buffer, 4 texels"
    name[16] = "copy shader: buffer, row"; name[17] = "copy shader: buffer, column"
    name[20] = "two-thread CPU copy (memcpy)"
    printf "%-6s %-38s %14s %10s\n", "size", "scheme", "instructions", "per texel"
  }
  { printf "%-6s %-38s %14d %10.1f\n", $1, name[$2], $3, $3 / ($1 * $1) }'
