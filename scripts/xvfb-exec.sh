#!/bin/bash
# Runs a command in a private virtual X server and exits with the command's status:
#   scripts/xvfb-exec.sh COMMAND [ARGS...]
# The viewer's tests use it instead of Debian's xvfb-run, which once turned a passing test into
# exit 5 ("problem while cleaning up temporary directory": its EXIT trap removes the directory of
# its Xauthority file while the server still runs). Here Xvfb picks a free display itself
# (-displayfd: it takes the lock file atomically, so servers started together never collide and
# the tests may run in parallel), only the local Unix socket is open (no TCP, no cookie to clean
# up), and the server is killed and waited for before the command's status is returned.
# Exit 3: Xvfb is not installed or did not start within 60 s (its messages on stderr).
set -u
command -v Xvfb >/dev/null || { echo "xvfb-exec: Xvfb is not installed (Debian: xvfb; scripts/bootstrap.sh)" >&2; exit 3; }
[[ $# -gt 0 ]] || { echo "usage: xvfb-exec.sh COMMAND [ARGS...]" >&2; exit 3; }

dir=$(mktemp -d -t msm-xvfb.XXXXXX) || exit 3
server=
stop() {
  if [[ -n $server ]]; then
    kill "$server" 2>/dev/null
    wait "$server" 2>/dev/null
  fi
  rm -rf "$dir"
}
trap stop EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

mkfifo "$dir/display"
Xvfb -displayfd 3 -nolisten tcp -screen 0 1280x1024x24 3>"$dir/display" 2>"$dir/log" &
server=$!
# Xvfb writes its display number when it accepts connections; end of file: it exited first.
display=
read -r -t 60 display <"$dir/display"
if [[ ! $display =~ ^[0-9]+$ ]]; then
  echo "xvfb-exec: Xvfb did not start:" >&2
  cat "$dir/log" >&2
  exit 3
fi

DISPLAY=:$display "$@"
status=$?
exit $status
