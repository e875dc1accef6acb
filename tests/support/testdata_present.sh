#!/bin/sh
# testdata_present.sh DIR — whether the shared test data (glTF samples, the Cornell box, X3D files)
# is at DIR. Without it the tests that read it skip (exit 77, each with the reason), and so does
# this one; with SY_REQUIRE_TESTDATA=1 in the environment (CI: .ci/run sets it) a missing DIR fails
# here instead, so that a run without the data is never green by skipping.
dir=$1
for sub in gltf cornell x3d; do
    if [ ! -d "$dir/$sub" ]; then
        if [ "${SY_REQUIRE_TESTDATA:-0}" = 1 ]; then
            echo "FAIL: SY_REQUIRE_TESTDATA=1 but $dir/$sub is absent (SY_TESTDATA_DIR names ../shared/testdata)"
            exit 1
        fi
        echo "SKIP: $dir/$sub is absent (the tests that read ../shared/testdata skip; SY_REQUIRE_TESTDATA=1 makes this a failure)"
        exit 77
    fi
done
echo "test data at $dir: gltf, cornell and x3d present"
