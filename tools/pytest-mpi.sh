#!/usr/bin/env bash
# Run pytest on every MPI rank; only rank 0 reports (mpich sets PMI_RANK).
if [ "${PMI_RANK:-0}" = "0" ]; then
  exec python -m pytest -p no:cacheprovider "$@"
else
  exec python -m pytest -p no:cacheprovider "$@" >/dev/null 2>&1
fi
