#!/usr/bin/env bash
# cluster_mpi_test.sh SY WORKDIR EXR_EQUAL — the MPI transport (issue 16): `mpirun -np 3 sy render ...
# --cluster mpi` runs rank 0 as the client and ranks 1-2 as render servers (3 ranks on this
# machine: oversubscribed, stated as such).
#   1. sort-first whitted over two server ranks: the EXR equals the local render byte for byte;
#   2. cooperative path tracing in side-by-side stereo: exactly the requested samples merged;
#      frames mode (--frames 0:3 --cluster-mode frames): every frame equal to a local sequence's;
#   3. bad input on rank 0 (a missing scene) ends every rank with an error, no hang; one rank
#      alone is refused with the reason; without a launcher, the reason is named.
# Skipped (77) when mpirun is missing or sy was built without MPI.
set -u
SY=$1; W=$2; EXR_EQUAL=${3:?exr_equal}
rm -rf "$W"; mkdir -p "$W"
fail() { echo "FAIL: $*" >&2; for f in "$W"/*.log; do echo "--- $f"; cat "$f"; done >&2; exit 1; }
command -v mpirun > /dev/null || { echo "skipped: mpirun is not installed (openmpi-bin)"; exit 77; }
"$SY" render demo -b whitted -w 8 -h 8 -o "$W/x.exr" --cluster mpi > /dev/null 2> "$W/nolaunch.log"
if grep -q "built without MPI" "$W/nolaunch.log"; then echo "skipped: sy was built without MPI"; exit 77; fi
grep -q "start sy under an MPI launcher" "$W/nolaunch.log" || fail "no launcher: the reason is not named"
# root in a container: Open MPI refuses root unless told; --oversubscribe: 3 ranks on 2 cores
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN=(timeout 500 mpirun --oversubscribe -np 3) # a hang guard: exit status 124

"$SY" render demo -b whitted -w 160 -h 120 -o "$W/local.exr" > /dev/null || fail "local render"
"${MPIRUN[@]}" "$SY" render demo -b whitted -w 160 -h 120 -o "$W/mpi.exr" --cluster mpi > "$W/sf.out" 2> "$W/sf.log" ||
  fail "mpirun sort-first render"
grep -q "whitted on 2 servers (sort-first)" "$W/sf.out" || fail "rank 0 did not render on 2 server ranks"
"$EXR_EQUAL" "$W/local.exr" "$W/mpi.exr" || fail "the MPI sort-first image differs from the local render"
grep -q "mpi rank 0 (stream [0-9]*): authenticated" "$W/sf.log" || fail "the server ranks did not authenticate rank 0"

"${MPIRUN[@]}" "$SY" render demo -b pathtracer --spp 24 -w 96 -h 64 --stereo sbs -o "$W/coop.exr" --cluster mpi \
  --cluster-mode cooperative > "$W/coop.out" 2> "$W/coop.log" || fail "mpirun cooperative stereo render"
grep -q "192x64, pathtracer on 2 servers (cooperative), 24 samples per pixel" "$W/coop.out" ||
  fail "cooperative stereo: not 192x64 with exactly 24 merged samples"

# frames mode over MPI: a 4-frame sequence, whole frames on the two server ranks, equal to a local one
"$SY" render demo -b whitted -w 48 -h 32 --frames 0:3 -o "$W/seq_l_#.exr" > /dev/null || fail "local sequence"
"${MPIRUN[@]}" "$SY" render demo -b whitted -w 48 -h 32 --frames 0:3 -o "$W/seq_m_#.exr" --cluster mpi \
  --cluster-mode frames > "$W/frames.out" 2> "$W/frames.log" || fail "mpirun frames mode"
grep -q "4 written, 0 skipped" "$W/frames.out" && grep -q "frames mode: 2 servers" "$W/frames.out" ||
  fail "frames mode over MPI: $(cat "$W/frames.out")"
for k in 0 1 2 3; do "$EXR_EQUAL" "$W/seq_l_$k.exr" "$W/seq_m_$k.exr" || fail "frames mode over MPI: frame $k differs"; done

"${MPIRUN[@]}" "$SY" render "$W/missing.gltf" -b whitted -o "$W/y.exr" --cluster mpi > /dev/null 2> "$W/bad.log"
rc=$?
[ $rc -ne 0 ] || fail "a missing scene on rank 0 succeeded"
[ $rc -ne 124 ] || fail "the ranks did not end after rank 0 failed (killed by the hang guard)"
grep -q "missing.gltf" "$W/bad.log" || fail "rank 0's error does not name the file"
[ ! -e "$W/y.exr" ] || fail "an image was written after a failure"
timeout 500 mpirun -np 1 "$SY" render demo -b whitted -o "$W/z.exr" --cluster mpi > /dev/null 2> "$W/one.log"
rc=$?
[ $rc -ne 0 ] || fail "a single rank was accepted"
[ $rc -ne 124 ] || fail "a single rank: killed by the hang guard"
grep -q "2..65 are needed" "$W/one.log" || fail "a single rank: the reason is not named"
echo "cluster_mpi: ok (3 ranks on $(nproc) cores: oversubscribed)"
