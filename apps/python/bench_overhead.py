"""bench_overhead.py: the call-overhead target of issue 38, measured by hand (not a timed test).

Setting a node's translation N times from Python (``node.translation = (i, 0.0, 0.0)``) against the
same N calls of sy_node_set_trs from C (switchyard._switchyard._bench_trs, in the same process on
the same scene), runs interleaved, best of R each; prints both and the ratio (target: at most 3),
in the thread's CPU time (not counting time the loaded machine gave to other processes) and in
wall-clock time.

    PYTHONPATH=BUILD/python /usr/bin/python3 apps/python/bench_overhead.py [N] [R]
"""
import os
import sys
import time

import numpy

# this folder holds the package's sources, not the built module: import the one on PYTHONPATH
_here = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != _here]
import switchyard  # noqa: E402
from switchyard import _switchyard as _c  # noqa: E402


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100000
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 7
    scene = switchyard.Scene()
    node = scene.add_mesh(numpy.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], numpy.float32))
    scene.commit()

    def python_loop():
        nd = node
        t0, c0 = time.perf_counter(), time.thread_time()
        for i in range(n):
            nd.translation = (i, 0.0, 0.0)
        c1, t1 = time.thread_time(), time.perf_counter()
        return t1 - t0, c1 - c0

    def c_loop():
        return _c._bench_trs(scene._c, node.id, n)

    inf = float("inf")
    best_c, best_py = [inf, inf], [inf, inf]
    for _ in range(runs):
        best_c = [min(a, b) for a, b in zip(best_c, c_loop())]
        scene.commit()
        best_py = [min(a, b) for a, b in zip(best_py, python_loop())]
        scene.commit()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print("N=%d, best of %d (load average %.2f, %d CPUs)" % (n, runs, load, os.cpu_count() or 0))
    for k, what in ((1, "CPU time"), (0, "wall time")):
        c, py = best_c[k], best_py[k]
        print("%-9s C sy_node_set_trs loop %.4f s (%.0f ns a call); Python node.translation = v %.4f s "
              "(%.0f ns a call); ratio %.2f (target <= 3)" % (what, c, 1e9 * c / n, py, 1e9 * py / n, py / c))
    scene.close()


if __name__ == "__main__":
    main()
