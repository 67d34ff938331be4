#!/bin/sh
# Whether two render JSON outputs (msm render) hold the same settings and view: every line but the
# device and the pass timings, which differ from run to run.
set -e
strip() {
  grep -v -E '^  "(device|gpu_ms|gpu_ms_total)"|^    "(blur|mipmaps|moment_resolve|prefix_sums|rectify|scattering|shading|shadow_depth|surfaces|one_pass_filter|sat)": |^  },?$' "$1"
}
strip "$1" > "$1.settings"
strip "$2" > "$2.settings"
diff "$1.settings" "$2.settings"
cat "$2"
