#!/usr/bin/env bash
# After ctest (make check, make sanitize): how many tests passed with some of their checks
# skipped, and which, read from ctest's log of the last run. A test that finds its data absent
# (the benchmark meshes of ../shared, the clean meshes, Python with numpy and scipy) or its device
# without a capability runs the rest and passes, saying so on a line of its output that ends in
# "skipped" or "skipping" or begins with "skipping "; ctest's "100% tests passed" does not show
# it. (A whole test that skips, exit 77, ctest lists itself as "Skipped"; it is not counted here.)
# Usage: scripts/skipped-checks.sh BUILD/Testing/Temporary/LastTest.log
# Prints nothing when no check was skipped; exits 0 either way (2 without a log).
set -euo pipefail
log=${1:?usage: $0 LastTest.log}
[ -r "$log" ] || { echo "skipped-checks: no ctest log at $log" >&2; exit 2; }
awk '
  /^[0-9]+\/[0-9]+ Testing: / { test = $3; inside = 0; pending = ""; next }
  /^Output:$/ { inside = 1; next }
  /^<end of output>$/ { inside = 0; next }
  inside && (/skipp(ed|ing)\.?$/ || /^skipping /) { pending = pending "    " $0 "\n"; next }
  /^Test Passed\.$/ && pending != "" { order[++n] = test; lines[test] = pending; pending = "" }
  END {
    if (n == 0) exit 0
    printf "%d test%s passed with checks skipped (data or a capability absent):\n", n,
           n == 1 ? "" : "s"
    for (i = 1; i <= n; i++) printf "  %s\n%s", order[i], lines[order[i]]
  }
' "$log"
