// The one translation unit that compiles tinygltf. Images are decoded by our own
// loader (scene/image.cpp), so tinygltf only keeps their bytes; stb_image is compiled
// once in stb_impl.cpp.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
// Image files are opened by scene/load_gltf.cpp through its FileScope, never by tinygltf.
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
