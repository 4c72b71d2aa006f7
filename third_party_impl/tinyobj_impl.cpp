// The one translation unit that compiles tinyobjloader (header-only here, so the
// render executable needs no shared library from the package).
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
