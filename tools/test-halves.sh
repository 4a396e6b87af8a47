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
  # per file: seconds in all, and seconds of tests that start mpirun -n 2 (they hold both
  # cores, so both halves wait for them); files not run keep their line
  shift
  log=$(mktemp) both=$(mktemp)
  paths=tests; for a in "$@"; do [[ $a == tests/* ]] && paths=; done
  BCFEM_TEST_CORES_LOG=$both "$PY" -m pytest -q -p no:cacheprovider --durations=0 "$@" $paths >"$log" 2>&1
  { head -2 "$WEIGHTS"
    { sed 's/ ([a-z]*)$//' "$both" | awk '{print "both", $1}'
      grep -E '^[0-9.]+s (call|setup|teardown)' "$log" | awk '{print "run", $1, $3}'
      tail -n +3 "$WEIGHTS" | awk '{print "old", $0}'
    } | awk '$1 == "both" {both[$2] = 1}
             $1 == "run" {split($3, a, "::"); t[a[1]] += $2; if ($3 in both) e[a[1]] += $2}
             $1 == "old" && !($2 in t) {old[$2] = $0}
             END {for (f in t) printf "%s %.1f %.1f\n", f, t[f], e[f]
                  for (f in old) print substr(old[f], 5)}' | sort -k2 -rn
  } >"$WEIGHTS.new" && mv "$WEIGHTS.new" "$WEIGHTS"
  rm -f "$log" "$both"
  exit 0
fi
# greedy on the seconds a file's tests run beside the other half: the longest first into the
# half that has less so far (unknown files: 1 s); both halves wait for the two-rank seconds
first=() second=() time_first=0 time_second=0
while read -r seconds file; do
  if (( time_first <= time_second )); then first+=("$file"); time_first=$((time_first + seconds))
  else second+=("$file"); time_second=$((time_second + seconds)); fi
done < <(for f in tests/test_*.py; do
           w=$(awk -v f="$f" '$1 == f {print int(($2 - $3) * 10 + 10)}' "$WEIGHTS"); echo "${w:-10} $f"
         done | sort -rn)
one=$(mktemp) two=$(mktemp) locks=$(mktemp -d)
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1  # one process per core: no threads besides
# a test that starts mpirun -n 2 takes both cores' locks; the other half waits (tests/cores.py)
BCFEM_TEST_CORES="$locks:0:2" "$PY" -m pytest -q -p no:cacheprovider --durations=5 "$@" "${first[@]}" >"$one" 2>&1 & a=$!
BCFEM_TEST_CORES="$locks:1:2" "$PY" -m pytest -q -p no:cacheprovider --durations=5 "$@" "${second[@]}" >"$two" 2>&1 & b=$!
wait $a; sa=$?
wait $b; sb=$?
cat "$one" "$two"
rm -rf "$one" "$two" "$locks"
exit $(( sa != 0 || sb != 0 ))
