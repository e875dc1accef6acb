"""python3 -m switchyard ARGS...: a thin alias of the sy program (docs/CLI.md), e.g.
``python3 -m switchyard render scene.gltf -o out.exr``. The program is taken from $SY_BIN, else
from PATH."""
import os
import shutil
import sys


def main():
    sy = os.environ.get("SY_BIN") or shutil.which("sy")
    if not sy:
        sys.stderr.write("python3 -m switchyard: the sy program was not found (set SY_BIN or put sy on PATH)\n")
        return 127
    os.execv(sy, [sy] + sys.argv[1:])


if __name__ == "__main__":
    sys.exit(main())
