// The gas's shadows on host surfaces (splatfx::shadowGlsl; docs/lighting.md),
// one table per shadowing light (splatfx::kMaxShadowLights slots). Mirrors
// ShadowTable::opticalDepth: the slab test moves a point outside the table
// along its ray to the light to where it enters the table. A zero direction
// component becomes +-1e30 in 1/d, which keeps points inside that slab
// unconstrained and those outside it rejected, with no 0 * inf.
const int splatfx_kMaxShadowLights = 4;  // splatfx::kMaxShadowLights
uniform sampler3D splatfx_shadowTable;  // slot 0 (SceneShadowDesc::light). R32F: optical depth towards the light, log2 units
uniform mat4 splatfx_worldToTable;      // world to the table's box [0, 1]^3
uniform vec4 splatfx_shadowLight;       // table space: position (w = 1) or travel direction (w = 0)
uniform sampler3D splatfx_shadowTable1, splatfx_shadowTable2, splatfx_shadowTable3; // slots 1 to 3, the same
uniform mat4 splatfx_worldToTable1, splatfx_worldToTable2, splatfx_worldToTable3;
uniform vec4 splatfx_shadowLight1, splatfx_shadowLight2, splatfx_shadowLight3;
uniform int splatfx_shadowLightIndex[splatfx_kMaxShadowLights]; // the scene light of each slot's table; -1 none

float splatfx_shadowIn(sampler3D table, mat4 worldToTable, vec4 light, vec3 worldPos) {
    vec3 p = (worldToTable * vec4(worldPos, 1.0)).xyz;
    bool isPoint = light.w > 0.5;
    vec3 d = isPoint ? light.xyz - p : -light.xyz;
    vec3 s = vec3(greaterThanEqual(d, vec3(0.0))) * 2.0 - 1.0;
    vec3 inv = s / max(abs(d), vec3(1e-30));
    vec3 ta = -p * inv, tb = (vec3(1.0) - p) * inv;
    vec3 tlo = min(ta, tb), thi = max(ta, tb);
    float tNear = max(max(max(tlo.x, tlo.y), tlo.z), 0.0);
    float tFar = min(min(thi.x, thi.y), thi.z);
    if (isPoint) tFar = min(tFar, 1.0);
    if (tNear > tFar) return 1.0;
    vec3 q = clamp(p + d * tNear, vec3(0.0), vec3(1.0));
    vec3 n = vec3(textureSize(table, 0));
    // One level, linear: no derivatives needed, so any control flow may call it.
    float depth = textureLod(table, (q * (n - 1.0) + 0.5) / n, 0.0).r;
    return exp2(-depth);
}

// Transmittance towards slot 0's light (SceneShadowDesc::light, light 0 by default).
float splatfx_shadow(vec3 worldPos) {
    return splatfx_shadowIn(splatfx_shadowTable, splatfx_worldToTable, splatfx_shadowLight, worldPos);
}

// Transmittance towards scene light `light` (an index into Scene::lights());
// 1 for a light without a table this frame.
float splatfx_shadowTo(int light, vec3 worldPos) {
    if (light < 0) return 1.0;
    if (light == splatfx_shadowLightIndex[0]) return splatfx_shadow(worldPos);
    if (light == splatfx_shadowLightIndex[1]) return splatfx_shadowIn(splatfx_shadowTable1, splatfx_worldToTable1, splatfx_shadowLight1, worldPos);
    if (light == splatfx_shadowLightIndex[2]) return splatfx_shadowIn(splatfx_shadowTable2, splatfx_worldToTable2, splatfx_shadowLight2, worldPos);
    if (light == splatfx_shadowLightIndex[3]) return splatfx_shadowIn(splatfx_shadowTable3, splatfx_worldToTable3, splatfx_shadowLight3, worldPos);
    return 1.0;
}

// Light from emissive volumes (splatfx::EmittedLight, emitted_light.hpp):
// point lights fitted to a fire's splats each frame. Mirrors
// splatfx::emittedIrradiance; count 0 (no emitter in the frame) gives 0.
const int splatfx_kMaxEmittedLights = 8;                            // splatfx::kMaxEmittedLights
uniform int splatfx_emittedLightCount;                              // <= splatfx_kMaxEmittedLights
uniform vec4 splatfx_emittedLightPosition[splatfx_kMaxEmittedLights]; // xyz world, w radius
uniform vec3 splatfx_emittedLightIntensity[splatfx_kMaxEmittedLights]; // linear RGB x world area
uniform vec3 splatfx_emittedLightEscapePlus[splatfx_kMaxEmittedLights];  // share leaving along +x, +y, +z
uniform vec3 splatfx_emittedLightEscapeMinus[splatfx_kMaxEmittedLights]; // ... along -x, -y, -z

vec3 splatfx_emittedIrradiance(vec3 worldPos, vec3 normal) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < min(splatfx_emittedLightCount, splatfx_kMaxEmittedLights); ++i) {
        vec3 d = splatfx_emittedLightPosition[i].xyz - worldPos;
        float d2 = dot(d, d);
        if (d2 <= 0.0) continue;
        vec3 w = -d * inversesqrt(d2); // from the light towards the point
        float cosine = max(dot(normal, -w), 0.0);
        vec3 escape = mix(splatfx_emittedLightEscapeMinus[i], splatfx_emittedLightEscapePlus[i], step(vec3(0.0), w));
        float r = splatfx_emittedLightPosition[i].w;
        sum += splatfx_emittedLightIntensity[i] * (dot(w * w, escape) * cosine / (d2 + r * r));
    }
    return sum;
}

// The irradiance grid alternative (splatfx::EmittedGrid, fitEmittedGrid):
// per node the irradiance for the normals +x, -x, +y, -y, +z, -z, RGB, packed
// 18 floats a node in vec4s. Mirrors splatfx::emittedIrradiance(grid, ...):
// trilinear from texelFetch-like exact reads (no filtering hardware, so the
// CPU and GLSL agree to float rounding); outside the box a point source at
// the centre calibrated at the box. Dims below 2 (no grid this frame) give 0.
const int splatfx_kMaxEmittedGridNodes = 32; // splatfx::kMaxEmittedGridNodes
uniform ivec3 splatfx_emittedGridDims;
uniform vec3 splatfx_emittedGridMin, splatfx_emittedGridMax, splatfx_emittedGridCentre;
uniform vec4 splatfx_emittedGrid[splatfx_kMaxEmittedGridNodes * 18 / 4];

vec3 splatfx_emittedGridValue(int node, int k) {
    int i = (node * 6 + k) * 3;
    return vec3(splatfx_emittedGrid[i >> 2][i & 3], splatfx_emittedGrid[(i + 1) >> 2][(i + 1) & 3], splatfx_emittedGrid[(i + 2) >> 2][(i + 2) & 3]);
}

vec3 splatfx_emittedGridIrradiance(vec3 worldPos, vec3 normal) {
    ivec3 n = splatfx_emittedGridDims;
    if (n.x < 2 || n.y < 2 || n.z < 2 || n.x * n.y * n.z > splatfx_kMaxEmittedGridNodes) return vec3(0.0);
    vec3 q = clamp(worldPos, splatfx_emittedGridMin, splatfx_emittedGridMax);
    vec3 t = (q - splatfx_emittedGridMin) / (splatfx_emittedGridMax - splatfx_emittedGridMin) * vec3(n - 1);
    ivec3 i0 = clamp(ivec3(floor(t)), ivec3(0), n - 2);
    vec3 f = t - vec3(i0);
    ivec3 k = ivec3(normal.x >= 0.0 ? 0 : 1, normal.y >= 0.0 ? 2 : 3, normal.z >= 0.0 ? 4 : 5);
    vec3 nn = normal * normal;
    vec3 sum = vec3(0.0);
    for (int c = 0; c < 8; ++c) {
        ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        vec3 w3 = mix(vec3(1.0) - f, f, vec3(o));
        ivec3 i = i0 + o;
        int node = (i.z * n.y + i.y) * n.x + i.x;
        sum += (w3.x * w3.y * w3.z) * (nn.x * splatfx_emittedGridValue(node, k.x) + nn.y * splatfx_emittedGridValue(node, k.y) +
                                       nn.z * splatfx_emittedGridValue(node, k.z));
    }
    if (all(equal(q, worldPos))) return sum;
    // Outside: a point source at the centre, its intensity read from q's six
    // values, on p's cosine; plus the grid's departure from it at q as d^-4.
    vec3 dq = splatfx_emittedGridCentre - q, dp = splatfx_emittedGridCentre - worldPos;
    float dq2 = dot(dq, dq), dp2 = dot(dp, dp);
    if (!(dq2 > 0.0) || !(dp2 > 0.0)) return sum;
    vec3 wq = dq / sqrt(dq2), wp = dp / sqrt(dp2);
    vec3 total = vec3(0.0);
    for (int c = 0; c < 8; ++c) {
        ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        vec3 w3 = mix(vec3(1.0) - f, f, vec3(o));
        ivec3 i = i0 + o;
        int node = (i.z * n.y + i.y) * n.x + i.x;
        total += (w3.x * w3.y * w3.z) * (splatfx_emittedGridValue(node, 0) + splatfx_emittedGridValue(node, 1) + splatfx_emittedGridValue(node, 2) +
                                          splatfx_emittedGridValue(node, 3) + splatfx_emittedGridValue(node, 4) + splatfx_emittedGridValue(node, 5));
    }
    vec3 intensity = total * (dq2 / (abs(wq.x) + abs(wq.y) + abs(wq.z)));
    vec3 atQ = intensity * (max(dot(normal, wq), 0.0) / dq2);
    vec3 atP = intensity * (max(dot(normal, wp), 0.0) / dp2);
    float r = dq2 / dp2;
    return max(atP + (sum - atQ) * (r * r), vec3(0.0));
}
