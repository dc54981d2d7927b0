#!/usr/bin/env bash
# Installs, builds and runs every test (unit, integration, 2-rank). CI calls this.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
scripts/install-deps.sh
scripts/build.sh
cd build
rc=0
ctest --output-on-failure --timeout 900 -j 2 || rc=$?
if [ "$rc" -ne 0 ]; then
  # CI shows the head and the tail of this output: repeat the failed checks at the end.
  echo "== failed checks (build/Testing/Temporary/LastTest.log) =="
  grep -E "^ *FAIL |\[  FAILED  \]|checks FAILED" Testing/Temporary/LastTest.log | head -60 || true
fi
exit "$rc"
