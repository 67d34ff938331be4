# Shared by scripts/callgrind-*.sh (sourced): run a program that marks its own dumps with callgrind
# client requests, on lavapipe, and print each dump's label and instruction total.
#
#   callgrind_run SCRIPT OUT PROGRAM ARGS...   valgrind --tool=callgrind --instr-atstart=no into
#                                              OUT/callgrind.out.*, the program's output in OUT/log;
#                                              on failure its last lines and exit 2 (SCRIPT names
#                                              the caller in the message)
#   callgrind_totals OUT TAG                   one line per dump: the words after "TAG " in the
#                                              dump's trigger, then its total Ir
#
# LP_NUM_THREADS=0: llvmpipe rasterizes and dispatches on the submitting thread, so no thread pool
# enters the counts; Mesa's shader cache is off so that every run compiles the same way.
callgrind_run() {
  local script=$1 out=$2
  shift 2
  command -v valgrind >/dev/null || { echo "$script: valgrind is not installed (scripts/bootstrap.sh)" >&2; exit 2; }
  local icd=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
  [[ -f $icd ]] && export VK_ICD_FILENAMES=$icd
  MESA_SHADER_CACHE_DISABLE=true LP_NUM_THREADS=0 valgrind --tool=callgrind --instr-atstart=no \
    --callgrind-out-file="$out/callgrind.out" "$@" >"$out/log" 2>&1 || {
    echo "$script: $(basename "$1") ${2:-} failed:" >&2
    tail -n 20 "$out/log" >&2
    exit 2
  }
}

callgrind_totals() {
  local out=$1 tag=$2 f
  for f in "$out"/callgrind.out.*; do
    awk -v tag="$tag" '$0 ~ "^desc: Trigger: Client Request: " tag " " { label = $0; sub(".*" tag " ", "", label) }
         /^totals:/ { ir = $2 }
         END { if (label != "") print label, ir }' "$f"
  done
}
