#!/bin/bash
# Runs a command with the other CPU-heavy processes of this machine (compilers, ninja,
# ctest, other lacerta runs, MPI) paused by SIGSTOP, then resumes them with SIGCONT.
# Used for the timings in doc/performance.md on a shared 2-core machine, e.g.
#   contrib/bench/quiet.sh build/lacerta-bench cut
# Keep such runs short: everything else waits meanwhile.
if [ $# -eq 0 ]; then
  echo "usage: $0 command [arguments...]" >&2
  exit 2
fi
me=$$
pids=$(ps -eo pid,ppid,comm --no-headers |
  awk -v me="$me" '$1 != me && $2 != me && ($3 ~ /^(cc1plus|ld|collect2|ninja|ctest|lacerta.*|mpirun|orted|make|cmake|as)$/) {print $1}')
[ -n "$pids" ] && kill -STOP $pids 2>/dev/null
trap '[ -n "$pids" ] && kill -CONT $pids 2>/dev/null' EXIT
sleep 1
"$@"
