#!/usr/bin/env bash
# scripts/skipped-checks.sh, which make check runs after ctest: a test that passed with some checks
# skipped (its data absent) is counted and named, with its lines; other tests, a test's own count
# of commands it was told to skip ("skipped (marked)"), and a whole test ctest skipped, are not.
set -uo pipefail
script=$1
. "$(dirname "$0")/command_util.sh"

cat >LastTest.log <<'LOG'
Start testing: Dec 07 06:18 UTC
----------------------------------------------------------
1/3 Testing: metrics
1/3 Test: metrics
Command: "/build/tests/test_metrics"
Output:
----------------------------------------------------------
metrics: 12 checks
benchmark meshes: /nowhere/data/benchmark absent, skipped
meshmetrics.py agreement: /nowhere/data/benchmark or /nowhere/tools/meshmetrics.py absent, skipped
<end of output>
Test time =   0.10 sec
----------------------------------------------------------
Test Passed.
2/3 Testing: docs_commands
2/3 Test: docs_commands
Output:
----------------------------------------------------------
docs_commands: 26 commands run, 27 skipped (marked), in 16 sh blocks of 15 files
<end of output>
Test Passed.
3/3 Testing: do_no_harm
3/3 Test: do_no_harm
Output:
----------------------------------------------------------
clean meshes: /nowhere/data/clean absent, skipped
<end of output>
Test Passed.
4/4 Testing: cl_grid
4/4 Test: cl_grid
Output:
----------------------------------------------------------
skipping (set RSMOOTH_REQUIRE_OPENCL=1 to make this a failure)
<end of output>
Test time =   0.01 sec
----------------------------------------------------------
Test Skipped.
End testing: Dec 07 06:19 UTC
LOG
expect 0 "$script" LastTest.log
head -1 out.txt | grep -qx "2 tests passed with checks skipped (data or a capability absent):" ||
  fail "no count of 2: $(cat out.txt)"
grep -qx "  metrics" out.txt && grep -qx "  do_no_harm" out.txt || fail "tests not named: $(cat out.txt)"
[ "$(grep -c 'absent, skipped' out.txt)" -eq 3 ] || fail "not the 3 lines: $(cat out.txt)"
grep -q docs_commands out.txt && fail "counted a test's marked skips: $(cat out.txt)"
grep -q cl_grid out.txt && fail "counted a test ctest skipped whole: $(cat out.txt)"

# nothing skipped: nothing printed
sed -i '/absent, skipped/d' LastTest.log
expect 0 "$script" LastTest.log
[ -s out.txt ] && fail "printed with nothing skipped: $(cat out.txt)"
# no log: said, status 2
expect 2 "$script" missing.log

[ "$failures" -eq 0 ] || exit 1
echo "all checks passed"
