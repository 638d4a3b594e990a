// The per-draw constants of the bake's vertex and fragment shaders (src/asset/bake.rs: DrawConstants).
layout(push_constant) uniform Draw {
    mat4 view_projection;   // world to clip, with the pass's sub-pixel jitter
    vec4 eye;               // xyz: the eye; w: 1 for a perspective camera, 0 for orthographic
    vec4 toward_eye;        // xyz: the unit direction toward an orthographic camera
    uint object_id;
    uint material;          // the material's place in the material table
    float lod_bias;         // −½·log2(samples): each sample's texture footprint is its share of the pixel
} draw;
