// The one translation unit that compiles stb_image and stb_image_write.
// Large or hostile images are refused before allocation (see scene/image.cpp).
#define STBI_MAX_DIMENSIONS (1 << 15)
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image.h>
#include <stb_image_write.h>
