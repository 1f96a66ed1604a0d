// The general cut variant's fragment (the splat pass and the fragment lists'
// sections): the splat's polygon crosses the eye plane, so the vertex stage
// covers the screen and each fragment meets its pixel ray with the splat's
// plane (the line, so a plane just behind the eye still gives its tail in
// front: continuous).
uniform mat4 uInvViewProj;
uniform vec4 uViewport; // x, y, width, height
uniform vec3 uEye;
uniform vec2 uNdcZ; // y: ndc z of a finite point beyond the near plane (the far plane's, when finite), giving each pixel's ray
uniform float uCut;
uniform int uOctagon;
flat in vec3 vCenter;
flat in vec3 vAxisU;
flat in vec3 vAxisV;

// The pixel ray's unit direction, its parameter at the plane and the hit in
// kernel units (uvk); false where the fragment is discarded (edge-on, or
// outside the drawn polygon).
bool splatfx_splat_plane(out vec3 dir, out float tP, out vec2 uvk) {
    vec2 ndc = (gl_FragCoord.xy - uViewport.xy) / uViewport.zw * 2.0 - 1.0;
    vec4 farPoint = uInvViewProj * vec4(ndc, uNdcZ.y, 1.0);
    dir = normalize(farPoint.xyz / farPoint.w - uEye);
    vec3 n = cross(vAxisU, vAxisV);
    float dn = dot(dir, n);
    bool edgeOn = abs(dn) <= 1e-6 * length(n);
    tP = dot(vCenter - uEye, n) / dn;
    vec3 g = uEye + tP * dir - vCenter;
    float g00 = dot(vAxisU, vAxisU), g01 = dot(vAxisU, vAxisV), g11 = dot(vAxisV, vAxisV);
    float b0 = dot(vAxisU, g), b1 = dot(vAxisV, g);
    uvk = vec2(g11 * b0 - g01 * b1, g00 * b1 - g01 * b0) / (g00 * g11 - g01 * g01);
    bool outside = max(abs(uvk.x), abs(uvk.y)) > uCut || (uOctagon != 0 && abs(uvk.x) + abs(uvk.y) > uCut * 1.41421356);
    return !edgeOn && !outside;
}
