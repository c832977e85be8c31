#!/usr/bin/env bash
# The man page (host/rsmooth.1) and the bash completion (host/rsmooth.bash-completion) are kept in
# step with the help texts: every long option `rsmooth --help` and the subcommands' --help name is
# in the man page and in the completion's list for that command, and neither names an option that
# no help text has.
set -uo pipefail
rsmooth=$1
source_dir=$2
man=$source_dir/host/rsmooth.1
completion=$source_dir/host/rsmooth.bash-completion
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
long_options() { grep -o -- '--[a-z][a-z0-9-]*' | sort -u; }
# the main help's synopsis lines of the subcommands name their options, not the main command's
help_main=$("$rsmooth" --help | grep -v '^ *rsmooth \(compare\|noise\|render\) ' | long_options)
# a subcommand's help may point at the main command's options ("rsmooth --confidence"): not its own
sub_options() { "$rsmooth" "$1" --help | sed 's/rsmooth --[a-z-]*//g' | long_options; }
help_compare=$(sub_options compare)
help_noise=$(sub_options noise)
help_render=$(sub_options render)
[ "$(echo "$help_main" | wc -l)" -gt 30 ] || fail "rsmooth --help names too few options: $help_main"
all=$(printf '%s\n' "$help_main" "$help_compare" "$help_noise" "$help_render" | sort -u)

# the man page: roff writes '-' as '\-'; its comment lines do not count
in_man=$(grep -v '^\.\\"' "$man" | sed 's/\\-/-/g; s/\\f[BIRP]//g' | long_options)
missing=$(comm -23 <(echo "$all") <(echo "$in_man"))
[ -z "$missing" ] || fail "rsmooth.1 lacks options the help names:" $missing
extra=$(comm -13 <(echo "$all") <(echo "$in_man"))
[ -z "$extra" ] || fail "rsmooth.1 names options no help has:" $extra

# the completion: one list per command, each exactly its help's options
flat=$(grep -v '^ *#' "$completion" | tr '\n' ' ')
for command in main compare noise render; do
  list=$(echo "$flat" | grep -o "local ${command}_options=\"[^\"]*\"" | sed 's/^[^"]*"//' |
         long_options)
  help_var=help_$command
  [ -n "$list" ] || fail "rsmooth.bash-completion has no ${command}_options list"
  missing=$(comm -23 <(echo "${!help_var}") <(echo "$list"))
  [ -z "$missing" ] || fail "completion of $command lacks:" $missing
  extra=$(comm -13 <(echo "${!help_var}") <(echo "$list"))
  [ -z "$extra" ] || fail "completion of $command offers options its help lacks:" $extra
done
extra=$(comm -13 <(echo "$all") <(echo "$flat" | long_options))
[ -z "$extra" ] || fail "rsmooth.bash-completion names options no help has:" $extra
bash -n "$completion" || fail "rsmooth.bash-completion is not valid bash"

# and it completes: options, values after '=' and after a space
out=$(bash -c '. "$1"; COMP_WORDS=(rsmooth in.ply --format=o); COMP_CWORD=2; _rsmooth;
               echo "${COMPREPLY[*]}"; COMP_WORDS=(rsmooth --sigma-); COMP_CWORD=1; _rsmooth;
               echo "${COMPREPLY[*]}"' _ "$completion")
[ "$out" = $'obj off\n--sigma-f --sigma-g --sigma-c' ] || fail "completion gives: $out"

echo "checked $(echo "$all" | wc -l) long options against rsmooth.1 and the completion"
[ "$failures" -eq 0 ] && echo "command docs: all checks passed" || echo "$failures failure(s)"
exit $((failures > 0))
