// The kernel's partial line integral (Footprint::fractionBefore in GLSL; docs/architecture.md,
// "The depth cut"). The footprint's constants precede this text (splatfx::partialGlsl):
// SPLATFX_PARTIAL_BINDING (the table's texture unit), SPLATFX_PARTIAL_RADIUS (R),
// SPLATFX_PARTIAL_X_SCALE, _X_BIAS, _Y_SCALE, _Y_BIAS (texel centres, so GL_LINEAR reproduces
// the CPU's bilinear lookup) and SPLATFX_PARTIAL_RADIUS_F (Footprint::radius(), a float).
layout(binding = SPLATFX_PARTIAL_BINDING) uniform sampler2D splatfx_partial_table;
// Fraction of the footprint F(r) at ray parameter <= s; r, s in kernel (voxel) units,
// s signed along the ray from its closest approach to the kernel centre.
float splatfx_partial_before(float r, float s) {
    const float R = SPLATFX_PARTIAL_RADIUS;
    float chord = sqrt(max(R * R - r * r, 0.0));
    float x = clamp(s / max(chord, 1e-6), -1.0, 1.0) * 0.5 + 0.5;
    float y = min(abs(r) / R, 1.0);
    vec2 tc = vec2(x * SPLATFX_PARTIAL_X_SCALE + SPLATFX_PARTIAL_X_BIAS, y * SPLATFX_PARTIAL_Y_SCALE + SPLATFX_PARTIAL_Y_BIAS);
    return texture(splatfx_partial_table, tc).r;
}
// World length of one kernel unit along a splat's centre ray (splats.hpp, splatRayScale):
// axisU, axisV its half-axes, code01 the top byte of Splat::color as a normalized float.
float splatfx_ray_scale(vec3 axisU, vec3 axisV, float code01) {
    float code = floor(code01 * 255.0 + 0.5);
    float rho = code > 254.5 ? 1.0 : exp2((code - 127.0) / 32.0);
    return rho * sqrt(length(cross(axisU, axisV))) / SPLATFX_PARTIAL_RADIUS_F;
}
