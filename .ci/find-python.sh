# Sourced by .ci/wheels.sh and .ci/wheels-check.sh: the CPython interpreters of one version on this
# machine. `pythons 3.11` prints each distinct one (its real path), one a line: python3.11 on PATH,
# /usr/bin/python3.11 and /usr/local/bin/python3.11, and pyenv's $PYENV_ROOT/versions/3.11.*/.
# A pyenv shim of a version not selected fails to run and is passed over; so is a Python without
# its headers (python3.X-dev: nothing can be built for it) when $1 is given as `--dev 3.X`.
pythons() {
  local dev=0
  if [ "$1" = --dev ]; then dev=1; shift; fi
  local v=$1 c real seen=" "
  local root=${PYENV_ROOT:-$HOME/.pyenv}
  for c in "$(command -v "python$v" 2>/dev/null || true)" "/usr/bin/python$v" "/usr/local/bin/python$v" \
           $(ls -d "$root"/versions/"$v".*/bin/"python$v" 2>/dev/null | sort -V); do
    [ -n "$c" ] && [ -x "$c" ] || continue
    real=$("$c" -c 'import os, sys; print(os.path.realpath(sys.executable))' 2>/dev/null) || continue
    case $seen in *" $real "*) continue ;; esac
    seen="$seen$real "
    if [ $dev = 1 ]; then
      "$real" -c 'import os, sysconfig, sys
sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' || continue
    fi
    echo "$real"
  done
}

# The first of them, or nothing (and status 0).
first_python() {
  local all
  all=$(pythons "$@")
  echo "${all%%$'\n'*}"
}
