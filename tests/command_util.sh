# Sourced by the command tests (test_command.sh, test_points_command.sh): a scratch directory to
# work in, removed on exit, and the checks they make.
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
# expect STATUS COMMAND...: runs it, checks the exit status, keeps stderr in err.txt
expect() {
  local want=$1; shift
  "$@" >out.txt 2>err.txt
  local got=$?
  [ "$got" -eq "$want" ] || fail "exit $got (wanted $want): $* -- $(cat err.txt)"
}
# expect_within SECONDS STATUS COMMAND...: as expect, and a command still running after SECONDS is
# killed and counted as a failure (a hang), not left to stall the suite.
expect_within() {
  local seconds=$1 want=$2; shift 2
  timeout -k 5 "$seconds" "$@" >out.txt 2>err.txt
  local got=$?
  if [ "$got" -eq 124 ] || [ "$got" -eq 137 ]; then
    fail "still running after $seconds s (a hang): $*"
  else
    [ "$got" -eq "$want" ] || fail "exit $got (wanted $want): $* -- $(cat err.txt)"
  fi
}
