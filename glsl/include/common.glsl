// Constants and small helpers shared by every kernel. Mirrored in src/shading/common.rs.
#ifndef LOOKDEV_COMMON_GLSL
#define LOOKDEV_COMMON_GLSL

const float PI = 3.14159265358979323846;
const float TWO_PI = 6.28318530717958647693;
const float INV_PI = 0.31830988618379067154;
const float INV_TWO_PI = 0.15915494309189533577;
// The largest float below 1: uniform samples must stay in [0, 1).
const float ONE_MINUS_EPSILON = 0.99999994;

// Rec.709 relative luminance, for importance weights.
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

#endif
