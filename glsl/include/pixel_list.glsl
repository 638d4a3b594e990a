// The compacted pixel lists (src/render/passes/pixel_lists.rs): an R32_UINT image read as a
// flat array of pixels packed x | y << 16.
#ifndef LOOKDEV_PIXEL_LIST_GLSL
#define LOOKDEV_PIXEL_LIST_GLSL

ivec2 unpack_pixel(uint packed) {
    return ivec2(int(packed & 0xffffu), int(packed >> 16));
}

// Entry `i` of a list stored row by row in an image `width` texels wide.
ivec2 list_texel(uint i, int width) {
    return ivec2(int(i % uint(width)), int(i / uint(width)));
}

#endif
