// ssbump_relief.hlsl: relief (parallax occlusion) mapping of a height map
// combined with Valve's self-shadowed bump map (ssbump) lighting, the
// shader functions `bumpbake render --view AZ,EL --relief` evaluates on the
// CPU (src/render/render.c, the same formulas; tests/render/test_relief.c
// holds the two together). HLSL, shader model 4 and up; the same functions
// as ssbump_relief.glsl, which says more about each.
//
// Frame: tangent space x right, y DOWN the texture (Source), z out of the
// surface; distances in texels; the polygon is z = depth (bake --scale), the
// surface z = depth * h. Maps read with a linear, wrapping sampler at mip 0;
// texel (i, j) sits at the point (i, j): uv = (p + 0.5) / size.

static const float3 SSBUMP_B0 = float3( 0.816496580927726,  0.0,               0.577350269189626);
static const float3 SSBUMP_B1 = float3(-0.408248290463863,  0.707106781186548, 0.577350269189626);
static const float3 SSBUMP_B2 = float3(-0.408248290463863, -0.707106781186548, 0.577350269189626);

float relief_h(Texture2D heightMap, SamplerState wrapLinear, float2 size, float2 p) {
    return heightMap.SampleLevel(wrapLinear, (p + 0.5) / size, 0.0).r;
}

// Where the view ray crossing the polygon at p meets the relief (view: unit,
// towards the viewer, view.z > 0): layers a horizontal half texel apart at
// most (1..1024), the crossing on the secant of the last two.
float2 relief_hit(Texture2D heightMap, SamplerState wrapLinear, float2 size, float2 p,
                  float3 view, float depth) {
    float reach = depth * length(view.xy) / view.z;
    float layers = clamp(ceil(2.0 * reach), 1.0, 1024.0);
    float dz = depth / layers;
    float2 dp = -view.xy / view.z * dz;
    float z = depth;
    float above = z - depth * relief_h(heightMap, wrapLinear, size, p);
    if (above <= 0.0) return p;
    [loop] for (int i = 0; i < (int)layers; i++) {
        float2 np = p + dp;
        float nz = z - dz;
        float below = nz - depth * relief_h(heightMap, wrapLinear, size, np);
        if (below <= 0.0) return p + above / (above - below) * dp;
        p = np;
        z = nz;
        above = below;
    }
    return p;
}

float3 ssbump_static(float3 s, float3 lightmap0, float3 lightmap1, float3 lightmap2) {
    return s.x * lightmap0 + s.y * lightmap1 + s.z * lightmap2;
}

float ssbump_dynamic(float3 s, float3 l) {
    float3 lb = float3(dot(l, SSBUMP_B0), dot(l, SSBUMP_B1), dot(l, SSBUMP_B2));
    return saturate(dot(s, lb));
}

float3 ssbump_bent_normal(float3 s) {
    float3 b = s.x * SSBUMP_B0 + s.y * SSBUMP_B1 + s.z * SSBUMP_B2;
    float len = length(b);
    return len > 0.0 ? b / len : float3(0.0, 0.0, 1.0);
}

float ssbump_specular(float3 n, float3 d, float3 view, float k) {
    if (dot(n, d) <= 0.0) return 0.0;
    float nh = dot(n, normalize(d + view));
    return nh > 0.0 ? pow(nh, k) : 0.0;
}

float3 ssbump_relief_shade(Texture2D heightMap, Texture2D ssbumpMap, SamplerState wrapLinear,
                           float2 size, float2 p, float3 view, float depth, float3 light,
                           float3 lightColor, float3 lightmap0, float3 lightmap1,
                           float3 lightmap2, float3 albedo, float specularExponent,
                           float specularStrength) {
    float2 hit = relief_hit(heightMap, wrapLinear, size, p, view, depth);
    float3 s = ssbumpMap.SampleLevel(wrapLinear, (hit + 0.5) / size, 0.0).rgb;
    float3 diffuse = ssbump_static(s, lightmap0, lightmap1, lightmap2) +
                     ssbump_dynamic(s, light) * lightColor;
    float3 rgb = albedo * diffuse;
    if (specularExponent > 0.0) {
        float3 n = ssbump_bent_normal(s);
        rgb += specularStrength * (lightColor * ssbump_specular(n, light, view, specularExponent) +
                                   lightmap0 * ssbump_specular(n, SSBUMP_B0, view, specularExponent) +
                                   lightmap1 * ssbump_specular(n, SSBUMP_B1, view, specularExponent) +
                                   lightmap2 * ssbump_specular(n, SSBUMP_B2, view, specularExponent));
    }
    return rgb;
}
