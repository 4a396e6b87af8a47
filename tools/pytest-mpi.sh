#!/usr/bin/env bash
# Run pytest on every MPI rank; only rank 0 reports (mpich sets PMI_RANK). Another
# rank's report is shown only when that rank fails (else a failure there would show
# as an exit code alone).
if [ "${PMI_RANK:-0}" = "0" ]; then
  exec python -m pytest -p no:cacheprovider "$@"
fi
log=$(mktemp)
python -m pytest -p no:cacheprovider "$@" >"$log" 2>&1
status=$?
if [ $status -ne 0 ]; then
  echo "=== rank ${PMI_RANK} failed (exit ${status}); its report: ===" >&2
  tail -n 60 "$log" >&2
fi
rm -f "$log"
exit $status
