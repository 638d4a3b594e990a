// The visibility grid (docs/formats.md#visibility): a square octahedral map of world directions,
// +Y at its centre, one bit per cell. Mirrored by Grid::cell in src/visibility/mod.rs.
#ifndef LOOKDEV_VISIBILITY_GLSL
#define LOOKDEV_VISIBILITY_GLSL

// The cell of the unit direction d on a grid of side × side cells, numbered row * side + column.
uint visibility_cell(vec3 d, uint side) {
    vec3 p = d / (abs(d.x) + abs(d.y) + abs(d.z));
    vec2 ab = p.y >= 0.0 ? p.xz
                         : vec2((1.0 - abs(p.z)) * (p.x >= 0.0 ? 1.0 : -1.0), (1.0 - abs(p.x)) * (p.z >= 0.0 ? 1.0 : -1.0));
    uvec2 cell = min(uvec2((ab * 0.5 + 0.5) * float(side)), uvec2(side - 1u));
    return cell.y * side + cell.x;
}

#endif
