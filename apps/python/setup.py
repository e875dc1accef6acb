"""Builds the extension module switchyard._switchyard with the repository's CMake project
(apps/python/CMakeLists.txt, target sy_python) and hands it to setuptools; pyproject.toml holds the
metadata. Environment: SY_CMAKE_ARGS (more -D options), SY_BUILD_JOBS (parallel jobs, default 2)."""
import os
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.path.join(os.path.abspath(self.build_temp), "cmake")
        cfg = ["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DSY_WITH_PYTHON=ON",
               "-DSY_BUILD_TESTS=OFF", "-DPython3_EXECUTABLE=" + sys.executable]
        if shutil.which("ninja"):
            cfg += ["-G", "Ninja"]
        cfg += shlex.split(os.environ.get("SY_CMAKE_ARGS", ""))
        subprocess.run(cfg, check=True)
        subprocess.run(["cmake", "--build", build, "--target", "sy_python", "-j", os.environ.get("SY_BUILD_JOBS", "2")],
                       check=True)
        built = os.path.join(build, "python", "switchyard", "_switchyard.abi3.so")
        out = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(out), exist_ok=True)
        shutil.copyfile(built, out)


setup(ext_modules=[Extension("switchyard._switchyard", sources=[], py_limited_api=True)],
      cmdclass={"build_ext": CMakeBuild},
      options={"bdist_wheel": {"py_limited_api": "cp311"}})
