# `pip install --no-build-isolation .` for the Python module (docs/python.md):
# CMake builds the native half _prast exactly as `cmake --build` does (the
# same libraries, flags and pixels) in pip's build folder, offline, with
# Debian's setuptools; the package is python/prast/. pybind11-dev,
# python3-dev and python3-numpy must be installed (scripts/install-deps.sh).
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

TOP = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(TOP, "CMakeLists.txt")) as f:
        for line in f:
            if line.startswith("project(prast VERSION "):
                return line.split()[2]
    return "0"


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        os.makedirs(build, exist_ok=True)
        configure = ["cmake", "-S", TOP, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DPRAST_TESTS=OFF",
                     "-DPRAST_PYTHON=ON", "-DPython_EXECUTABLE=" + sys.executable]
        if os.environ.get("CMAKE_CXX_COMPILER_LAUNCHER"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=" + os.environ["CMAKE_CXX_COMPILER_LAUNCHER"])
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 2))
        subprocess.run(["cmake", "--build", build, "-j", jobs, "--target", "_prast"], check=True)
        built = [f for f in os.listdir(os.path.join(build, "python", "prast")) if f.startswith("_prast")]
        if len(built) != 1:
            raise RuntimeError("the CMake build made no single _prast module: %s" % built)
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(build, "python", "prast", built[0]), target)


setup(
    name="prast",
    version=version(),
    description="Deterministic physically based software rasterizer: renders as numpy arrays, pixel tests",
    packages=["prast"],
    package_dir={"prast": "python/prast"},
    ext_modules=[Extension("prast._prast", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.9",
    zip_safe=False,
)
