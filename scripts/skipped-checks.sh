#!/usr/bin/env bash
# After ctest (make check, make sanitize): how many tests skipped part of their checks, and which,
# read from ctest's log of the last run. A test that finds its data absent (the benchmark meshes
# of ../shared, the clean meshes, Python with numpy and scipy) runs the rest and passes, saying
# on a line of its output that ends in "skipped"; ctest's "100% tests passed" does not show it.
# (Whole tests that skip, exit 77, ctest lists itself as "Skipped".)
# Usage: scripts/skipped-checks.sh BUILD/Testing/Temporary/LastTest.log
# Prints nothing when no check was skipped; exits 0 either way (2 without a log).
set -euo pipefail
log=${1:?usage: $0 LastTest.log}
[ -r "$log" ] || { echo "skipped-checks: no ctest log at $log" >&2; exit 2; }
awk '
  /^[0-9]+\/[0-9]+ Testing: / { test = $3; inside = 0; next }
  /^Output:$/ { inside = 1; next }
  /^<end of output>$/ { inside = 0; next }
  inside && /skipped\.?$/ && !/^-+$/ {
    if (!(test in seen)) { seen[test] = 1; order[++n] = test }
    lines[test] = lines[test] "    " $0 "\n"
  }
  END {
    if (n == 0) exit 0
    printf "%d test%s passed with checks skipped (their data absent):\n", n, n == 1 ? "" : "s"
    for (i = 1; i <= n; i++) printf "  %s\n%s", order[i], lines[order[i]]
  }
' "$log"
