#!/usr/bin/env bash
# A tier's serial tests in two pytest processes side by side (one per core: each test is a
# serial solve), then both reports; exits non-zero if either failed. Arguments go to pytest
# (none: the fast tier; `-m "not study"`: every test but the studies). The files are split into
# halves of about equal time by $WEIGHTS (default tools/test-durations.txt, the fast tier's;
# tools/test-durations-all.txt is the full tier's); `--record [ARGS]` measures it again.
set -u
cd "$(dirname "$0")/.."
PY=${PY:-.venv/bin/python}
WEIGHTS=${WEIGHTS:-tools/test-durations.txt}
if [ "${1:-}" = "--record" ]; then
  shift
  log=$(mktemp)
  "$PY" -m pytest -q -p no:cacheprovider --durations=0 "$@" tests >"$log" 2>&1
  { head -2 "$WEIGHTS"
    grep -E '^[0-9.]+s (call|setup|teardown)' "$log" \
      | awk '{split($3, a, "::"); t[a[1]] += $1} END {for (f in t) printf "%s %.1f\n", f, t[f]}' | sort -k2 -rn
  } >"$WEIGHTS.new" && mv "$WEIGHTS.new" "$WEIGHTS"
  rm -f "$log"
  exit 0
fi
# greedy: the longest file first into the half that has less so far (unknown files: 1 s)
first=() second=() time_first=0 time_second=0
while read -r seconds file; do
  if (( time_first <= time_second )); then first+=("$file"); time_first=$((time_first + seconds))
  else second+=("$file"); time_second=$((time_second + seconds)); fi
done < <(for f in tests/test_*.py; do
           w=$(awk -v f="$f" '$1 == f {print int($2 * 10 + 10)}' "$WEIGHTS"); echo "${w:-10} $f"
         done | sort -rn)
one=$(mktemp) two=$(mktemp)
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1  # one process per core: no threads besides
"$PY" -m pytest -q -p no:cacheprovider --durations=5 "$@" "${first[@]}" >"$one" 2>&1 & a=$!
"$PY" -m pytest -q -p no:cacheprovider --durations=5 "$@" "${second[@]}" >"$two" 2>&1 & b=$!
wait $a; sa=$?
wait $b; sb=$?
cat "$one" "$two"
rm -f "$one" "$two"
exit $(( sa != 0 || sb != 0 ))
