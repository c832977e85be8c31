#!/usr/bin/env bash
# The man page (host/rsmooth.1) and the bash completion (host/rsmooth.bash-completion) are kept in
# step with the help texts: every long option `rsmooth --help` and the subcommands' --help name is
# in the man page and in the completion's list for that command, and neither names an option that
# no help text has. Then the docs against the program and against each other (below: "The docs
# agree"): what --best runs and stage_repeats' range as the command reports them, README's speed
# and accuracy figures as the pages they quote, every ctest test in docs/building.md's table, and
# every relative link to a file that exists.
# usage: test_command_docs.sh BUILD/rsmooth SOURCE_DIR [CTEST]
set -uo pipefail
rsmooth=$1
source_dir=$2
ctest_command=${3:-ctest}
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

# ---- The docs agree, with the program and with each other -----------------------------------
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
src=$source_dir
# has FILE TEXT: FILE holds TEXT (fixed string; line breaks and indents read as one space)
flat() { tr '\n' ' ' <"$src/$1" | tr -s ' '; }
has() { flat "$1" | grep -qF -- "$2" || fail "$1 does not say '$2'"; }
hasnt() { ! flat "$1" | grep -qF -- "$2" || fail "$1 still says '$2'"; }

# What --best runs, from the command's own --json report: the help, the man page and the Python
# pages say the same cycles, rounds and updates.
demo_shape=$(dirname "$rsmooth")/rsmooth-demo-shape
if [ -x "$demo_shape" ]; then
  "$demo_shape" make "$work/n.ply" "$work/t.ply" --noise 0.3 --triangles 500 >/dev/null
  report=$("$rsmooth" "$work/n.ply" -o "$work/o.ply" --best --device reference --json -q 2>&1)
  field() { echo "$report" | grep -o "\"$1\":[0-9]*" | head -1 | cut -d: -f2; }
  cycles=$(field stage_repeats) rounds=$(field guided_rounds) updates=$(field vertex_updates)
  [ -n "$cycles" ] && [ -n "$rounds" ] && [ -n "$updates" ] || fail "--best --json: $report"
  round_word=rounds
  [ "$rounds" = 1 ] && round_word=round
  # the help read whole first: grep -q stops reading at its match, and the command would then
  # die of SIGPIPE (pipefail), as it does under the sanitizers
  grep -qF "In --best: $updates per cycle, $cycles cycles." <<<"$("$rsmooth" --help)" ||
    fail "rsmooth --help does not say --best's $updates updates per cycle, $cycles cycles"
  for page in host/rsmooth.1 docs/python.md python/README.md; do
    has "$page" "$cycles cycles, each fresh facet normals, $rounds guided $round_word and $updates"
  done
  # a missing output folder is made (docs/command.md says so)
  "$rsmooth" "$work/n.ply" -o "$work/missing/sub/o.ply" -q --device reference &&
    [ -f "$work/missing/sub/o.ply" ] || fail "-o into a missing folder did not make it"
  has docs/command.md "a missing output folder is made with"
  hasnt docs/command.md "its folder is missing or not writable"
else
  fail "no rsmooth-demo-shape beside $rsmooth"
fi
for page in host/rsmooth.1 docs/python.md python/README.md; do hasnt "$page" "repeated 5 times"; done
hasnt python/README.md "4 guided rounds"
hasnt docs/python.md "4 guided rounds"
# stage_repeats' range as the command refuses it
range=$("$rsmooth" "$work/n.ply" -o "$work/x.ply" --stage-repeats 0 2>&1 | grep -o '\[1, [0-9]*\]')
top=${range#[1, }
top=${top%]}
[ -n "$top" ] || fail "--stage-repeats 0 gave no range"
has docs/python.md "\`stage_repeats\` 1–$top"
has python/README.md "\`stage_repeats\` 1 to $top"
grep -qF -- "--stage-repeats K     the stage's cycles (1..$top," <<<"$("$rsmooth" --help)" ||
  fail "rsmooth --help gives another range for --stage-repeats than [1, $top]"
grep -qF "cycles (1 to $top," "$src/host/rsmooth.1" || fail "rsmooth.1: --stage-repeats not 1 to $top"

# README's speed table, quoted from docs/performance.md: each figure is in that page's row for
# the same mesh (Bunny0.2's case row, the scaling table's 1M and 16M rows).
perf=$src/docs/performance.md
rows=$(awk '/^## How fast/{t=1} /^## /&&!/How fast/{t=0} t&&/^\| (Bunny|generated)/' "$src/README.md")
[ "$(echo "$rows" | grep -c .)" -ge 3 ] || fail "README's speed table not found"
while IFS= read -r row; do
  label=$(echo "$row" | cut -d'|' -f2)
  case $label in
    *Bunny0.2*) key='^| Bunny0.2, σ 2 / 0.5 |' ;;
    *" 1M "*) key='^| 1M |' ;;
    *" 16M "*) key='^| 16M |' ;;
    *) fail "README speed row not known: $row"; continue ;;
  esac
  line=$(grep -E "$(echo "$key" | sed 's/|/\\|/g')" "$perf" | head -1)
  [ -n "$line" ] || { fail "docs/performance.md has no row $key"; continue; }
  for figure in $(echo "$row" | cut -d'|' -f3- | grep -oE '[0-9.]+ (ms|s|ns)' | tr ' ' '_'); do
    figure=${figure//_/ }
    echo "$line" | grep -qF -- "$figure" || fail "README's '$figure' ($label) is not in performance.md's row: $line"
  done
done <<<"$rows"
tiles=$(grep -oE 'in 8 tiles: \+[0-9]+%' "$src/README.md" | grep -oE '\+[0-9]+%')
[ -n "$tiles" ] && grep -qF "**$tiles**" "$perf" || fail "README's tiles cost '$tiles' is not performance.md's"
for figure in "6.5–8.8 s" "15–20 ms"; do
  flat README.md | grep -qF "$figure" && flat docs/performance.md | grep -qF "$figure" ||
    fail "'$figure' is not in both README.md and docs/performance.md"
done
for page in docs/building.md README.md; do
  for figure in $(grep -oE '(build|cache)[^.]{0,80}[0-9.]+–[0-9.]+ (s|ms)' "$src/$page" |
                  grep -oE '[0-9.]+–[0-9.]+_?(s|ms)' | tr ' ' '_'); do
    grep -qF "${figure//_/ }" "$perf" || fail "$page's '${figure//_/ }' is not in performance.md"
  done
done

# README's accuracy table: noisy and paper-filter figures from docs/experiments.md, the rest from
# docs/accuracy.md's row of the same model.
acc=$src/docs/accuracy.md
rows=$(awk '/^## How accurate/{t=1} /^## /&&!/How accurate/{t=0} t&&/^\| [A-Z][A-Za-z]*[0-9.]+ \|/' "$src/README.md")
[ "$(echo "$rows" | grep -c .)" -ge 3 ] || fail "README's accuracy table not found"
while IFS= read -r row; do
  model=$(echo "$row" | cut -d'|' -f2 | tr -d ' ')
  for column in 3 4; do
    figure=$(echo "$row" | cut -d'|' -f$column | tr -d ' ')
    grep -qF -- "$figure" "$src/docs/experiments.md" || fail "README's $model $figure is not in docs/experiments.md"
  done
  line=$(grep -E "^\| $model \| [0-9.]+ [gi] \|" "$acc" | head -1)
  [ -n "$line" ] || { fail "docs/accuracy.md has no row for $model"; continue; }
  shipped=$(echo "$row" | cut -d'|' -f5 | tr -d ' ')
  left_out=$(echo "$row" | cut -d'|' -f6 | tr -d ' ')
  # the row: | case | est. noise | left out E_v / θ | as shipped E_v / θ | ...
  [ "$(echo "$line" | cut -d'|' -f4 | awk '{print $1}')" = "$left_out" ] ||
    fail "README's left-out $model $left_out is not accuracy.md's: $line"
  [ "$(echo "$line" | cut -d'|' -f5 | awk '{print $1}')" = "$shipped" ] ||
    fail "README's as-shipped $model $shipped is not accuracy.md's: $line"
  anchor=$(echo "$row" | cut -d'|' -f7 | awk '{print $1}')
  grep -E "^\| $model \|" "$acc" | grep -qF -- "$anchor" || fail "README's anchor $model $anchor is not in accuracy.md"
done <<<"$rows"
for figure in "median 1.13×" "worst 1.94×"; do
  flat README.md | grep -qF "$figure" && flat docs/accuracy.md | grep -qF "$figure" ||
    fail "'$figure' not in both README and accuracy.md"
done
below=$(grep -oE 'settings on [0-9]+ \(E_v\)' "$src/README.md" | grep -oE '[0-9]+')
grep -qF "At or below GMNF's defaults: E_v $below of 30" "$acc" || fail "README's $below cases at or below GMNF is not accuracy.md's"

# Every ctest test is in docs/building.md's table of tests.
build_dir=$(cd "$(dirname "$rsmooth")" && pwd)
if tests=$(cd "$build_dir" && "$ctest_command" -N 2>/dev/null | awk '/Test +#/{print $3}') &&
   [ -n "$tests" ]; then
  documented=$(awk -F'|' '/^\| test \| oracle/{t=1;next} t&&/^\|/{print $2} t&&!/^\|/{t=0}' \
               "$src/docs/building.md" | grep -o '`[a-z0-9_]*`' | tr -d '`' | sort -u)
  missing=$(comm -23 <(echo "$tests" | sort -u) <(echo "$documented"))
  [ -z "$missing" ] || fail "docs/building.md's table of tests lacks:" $missing
else
  echo "skipped the table of tests: no ctest -N in $build_dir"
fi

# Every relative link in the project's pages names a file that exists; the package's own page
# (python/README.md, which PyPI shows without the tree) has none.
pages=$(cd "$src" && ls README.md CONTRIBUTING.md lib/README.md blender/README.md docs/*.md docs/maintainers/*.md)
links=0
for page in $pages; do
  dir=$(dirname "$src/$page")
  while IFS= read -r target; do
    [ -n "$target" ] || continue
    links=$((links + 1))
    file=${target%%#*}
    [ -z "$file" ] || [ -e "$dir/$file" ] || fail "$page links to $target, which does not exist"
  done < <(grep -oE '\]\([^)]+\)' "$src/$page" | sed 's/^](//; s/)$//' | grep -vE '^(https?:|mailto:)')
done
! grep -qE '\]\((\.\./|docs/)' "$src/python/README.md" || fail "python/README.md has relative links (PyPI shows it alone)"
echo "checked $links relative links"
[ "$failures" -eq 0 ] && echo "command docs: all checks passed" || echo "$failures failure(s)"
exit $((failures > 0))
