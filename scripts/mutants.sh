#!/usr/bin/env bash
# Mutation check: applies each one-line (or few-line) bug listed in
# scripts/mutants.list to a scratch copy of the tree, rebuilds only the tests
# named for it, runs them, and reports the mutant "killed" when one of them
# fails, "SURVIVED" when all pass. Exits 1 when any mutant survived or could
# not be applied or built, so a survivor is never mistaken for a pass.
#   scripts/mutants.sh                 every mutant in scripts/mutants.list
#   scripts/mutants.sh NAME...         only these
#   scripts/mutants.sh --list          names and what each breaks
# The scratch copy and its build live in ${IMUSYSID_MUTANTS_DIR:-/tmp/
# imusysid-mutants} and are reused, so a second run rebuilds only what changed.
# Adding a mutant: docs/testing.md ("Mutants").
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
list=scripts/mutants.list
scratch=${IMUSYSID_MUTANTS_DIR:-/tmp/imusysid-mutants}

# Reads the list into parallel arrays; blocks are separated by blank lines,
# each line is "key value" with key one of name, file, from, to, tests, why.
names=() files=() froms=() tos=() tests=() whys=()
parse() {
  local name="" file="" from="" to="" test="" why="" key value
  flush() {
    if [ -n "$name" ]; then
      names+=("$name") files+=("$file") froms+=("$from") tos+=("$to")
      tests+=("$test") whys+=("$why")
    fi
    name="" file="" from="" to="" test="" why=""
  }
  while IFS= read -r line || [ -n "$line" ]; do
    case "$line" in
      '#'*) continue ;;
      '') flush; continue ;;
    esac
    key=${line%% *}
    value=${line#* }
    case "$key" in
      name) name=$value ;;
      file) file=$value ;;
      from) from=$value ;;
      to) to=$value ;;
      tests) test=$value ;;
      why) why=$value ;;
      *) echo "mutants.sh: $list: unknown key '$key' in: $line" >&2; exit 2 ;;
    esac
  done < "$list"
  flush
}
parse

if [ "${1:-}" = "--list" ]; then
  for i in "${!names[@]}"; do printf '%-28s %s\n' "${names[$i]}" "${whys[$i]}"; done
  exit 0
fi
if [ "${1:-}" = "-h" ] || [ "${1:-}" = "--help" ]; then sed -n '2,12p' "$0"; exit 0; fi

selected=()
if [ $# -gt 0 ]; then
  for want in "$@"; do
    found=0
    for i in "${!names[@]}"; do
      if [ "${names[$i]}" = "$want" ]; then selected+=("$i"); found=1; fi
    done
    [ $found = 1 ] || { echo "mutants.sh: no mutant named '$want' (--list)" >&2; exit 2; }
  done
else
  selected=("${!names[@]}")
fi

# The scratch copy: tracked and untracked (not ignored) files, a file copied
# only when it differs, so the build there stays incremental.
mkdir -p "$scratch/src"
git ls-files -co --exclude-standard -z | while IFS= read -r -d '' f; do
  [ -f "$f" ] || continue
  if ! cmp -s "$f" "$scratch/src/$f" 2>/dev/null; then
    mkdir -p "$scratch/src/$(dirname "$f")"
    # A new time stamp, not the original's: a file edited while an earlier
    # run was building could otherwise look older than its objects there.
    cp "$f" "$scratch/src/$f"
  fi
done
src=$scratch/src
bld=$scratch/build
cmake -S "$src" -B "$bld" -DCMAKE_BUILD_TYPE=Release -DIMUSYSID_WERROR=OFF \
  -DIMUSYSID_BUILD_BENCHMARKS=OFF >/dev/null
# Real logs from ../shared beside this checkout, not beside the scratch copy.
if [ -d "$repo/../shared/data/real" ]; then
  export IMUSYSID_REAL_DATA_DIR="$repo/../shared/data/real"
fi

# Applies (or checks) one replacement: exactly one occurrence of `from`
# (with \n for a line break) must exist.
substitute() {  # file from to
  python3 - "$1" "$2" "$3" <<'PY'
import sys
path, old, new = sys.argv[1], sys.argv[2].replace("\\n", "\n"), sys.argv[3].replace("\\n", "\n")
text = open(path, encoding="utf-8").read()
count = text.count(old)
if count != 1:
    print(f"'from' occurs {count} times in {path}", file=sys.stderr)
    sys.exit(1)
open(path, "w", encoding="utf-8").write(text.replace(old, new))
PY
}

jobs=$(nproc)
start=$SECONDS
killed=0 survived=0 invalid=0
summary=()
for i in "${selected[@]}"; do
  name=${names[$i]} file=${files[$i]}
  read -r -a targets <<< "${tests[$i]}"
  t0=$SECONDS
  cp -p "$src/$file" "$scratch/original"
  status=""
  if ! substitute "$src/$file" "${froms[$i]}" "${tos[$i]}"; then
    status="INVALID (not applied)"
  else
    # The tool too, always: many test files hold CLI cases beside their unit
    # cases, and without it those fail (exit 127) and would count the
    # mutant killed whatever the unit cases said.
    build_targets=("${targets[@]}" imusysid_cli)
    if ! cmake --build "$bld" -j"$jobs" --target "${build_targets[@]}" \
        > "$scratch/build.log" 2>&1; then
      status="INVALID (does not build: $scratch/build.log)"
    else
      status="SURVIVED"
      for t in "${targets[@]}"; do
        if ! timeout 900 "$bld/tests/$t" --gtest_brief=1 > "$scratch/$name.$t.log" 2>&1; then
          status="killed by $t"
          break
        fi
      done
    fi
  fi
  # Restore the file's content and time stamp, so the next build sees the
  # original again.
  cp -p "$scratch/original" "$src/$file"
  touch "$src/$file"
  case "$status" in
    killed*) killed=$((killed + 1)) ;;
    SURVIVED) survived=$((survived + 1)) ;;
    *) invalid=$((invalid + 1)) ;;
  esac
  line=$(printf '%-28s %-44s %4d s' "$name" "$status" $((SECONDS - t0)))
  echo "$line"
  summary+=("$line")
done
total=${#selected[@]}
echo "mutants: $killed killed, $survived survived, $invalid invalid of $total ($((SECONDS - start)) s)"
[ $survived -eq 0 ] && [ $invalid -eq 0 ]
