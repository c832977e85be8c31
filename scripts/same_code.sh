#!/usr/bin/env bash
# Compares the machine code of every library object file between two build folders (before and
# after a move of source files): objdump's disassembly with relocations, the file name line left
# out, per source file found in both by its base name. Prints "same" or "differs" per file.
#   scripts/same_code.sh build-before build-after
set -uo pipefail
old=$1 new=$2
same=0 differ=0
while IFS= read -r o; do
  base=$(basename "$o")
  n=$(find "$new/CMakeFiles" -name "$base" -path '*rsmooth*.dir/lib/*' | head -1)
  [ -n "$n" ] || { echo "gone     ${o#"$old"/CMakeFiles/}"; continue; }
  if cmp -s <(objdump -d -r --no-show-raw-insn "$o" | tail -n +3) \
    <(objdump -d -r --no-show-raw-insn "$n" | tail -n +3); then
    same=$((same + 1))
  else
    differ=$((differ + 1))
    echo "differs  ${n#"$new"/CMakeFiles/}"
  fi
done < <(find "$old/CMakeFiles" -name '*.c.o' -path '*rsmooth*.dir/lib/*' | sort)
echo "library objects with the same code: $same; differing: $differ"
