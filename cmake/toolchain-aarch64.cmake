# Cross build for aarch64 Linux on a Debian 12 amd64 host (issue 26: the same
# bytes on every compiler and CPU). scripts/install-deps-aarch64.sh installs
# the cross compiler and qemu-user and unpacks the arm64 static libraries into
# a sysroot folder. Use:
#   cmake -S . -B ../build-aarch64 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-aarch64.cmake
#   qemu-aarch64 ../build-aarch64/render -o out.png
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# CMake does not derive it from the cross compiler's directories (they are
# /usr/aarch64-linux-gnu/lib, not lib/aarch64-linux-gnu), and find_library
# needs it to look in the sysroot's usr/lib/aarch64-linux-gnu.
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

if(NOT PRAST_AARCH64_SYSROOT)
  if(DEFINED ENV{PRAST_AARCH64_SYSROOT})
    set(PRAST_AARCH64_SYSROOT "$ENV{PRAST_AARCH64_SYSROOT}")
  else()
    set(PRAST_AARCH64_SYSROOT /opt/prast-aarch64-sysroot)
  endif()
endif()
set(PRAST_AARCH64_SYSROOT "${PRAST_AARCH64_SYSROOT}" CACHE PATH
    "arm64 libraries unpacked by scripts/install-deps-aarch64.sh")
# try_compile projects read the toolchain again; they need the same sysroot.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES PRAST_AARCH64_SYSROOT)

# Libraries and CMake packages only from the arm64 trees, never the host's
# x86-64 ones. Headers from both: the sysroot's, then the host's /usr/include
# (the cross compiler searches it too), which holds the header-only libraries
# and the same headers as the sysroot for the Multi-Arch: same packages.
set(CMAKE_FIND_ROOT_PATH "${PRAST_AARCH64_SYSROOT}" /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
# glm is header-only (libglm-dev is Architecture: all): the host's package.
set(glm_DIR /usr/share/cmake/glm CACHE PATH "glm's CMake package (header-only)")

# The baseline ISA: every aarch64 CPU has Advanced SIMD (NEON), which GCC's
# vectoriser uses for the portable lane loops; the x86 paths are under
# __AVX2__ and stay out. Set before CMakeLists.txt offers x86-64-v3.
set(PRAST_MARCH "armv8-a" CACHE STRING "Target ISA for -march")

# The Python module would be an aarch64 extension for the host's x86-64
# interpreter: never loadable, so not built.
set(PRAST_PYTHON OFF CACHE STRING "Build the Python module prast: ON, OFF or AUTO")

# Fully static executables: qemu-aarch64 runs them with no -L and no arm64
# loader or libc on the host.
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64)
