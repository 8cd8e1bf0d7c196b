// ssbump_relief.glsl: relief (parallax occlusion) mapping of a height map
// combined with Valve's self-shadowed bump map (ssbump) lighting, the
// shader functions `bumpbake render --view AZ,EL --relief` evaluates on the
// CPU (src/render/render.c, the same formulas; tests/render/test_relief.c
// holds the two together). GLSL 3.30 / ES 3.00; copy what you need.
//
// Frame (docs/conventions.md): tangent space x to the right of the texture,
// y DOWN it (Source's "+Y down"; flip y of view and light vectors for an
// OpenGL-style texture), z out of the surface. Distances are in texels: the
// relief's top plane, the polygon, is z = depth (bake --scale: texels of
// displacement per unit of height), the surface under it z = depth * h with
// h the height map in [0, 1]. Maps are read bilinearly and tile
// (GL_LINEAR, GL_REPEAT); texel (i, j) of a map of `size` texels sits at
// the point (i, j), so a point p reads uv = (p + 0.5) / size. Mip level 0
// throughout: the relief loop's derivatives are not defined.
//
// The ssbump holds s_c = max(0, N.B_c) vis_c (bake --ssbump, Valve's
// height2ssbump): the weights Source multiplies its three lightmap colours
// by, with the surface's self-shadowing (and, baked with --bounce, the light
// its relief reflects) in them. Relief mapping moves where the map is read;
// the ssbump then shades the point met, shadowed by its own relief.

const vec3 SSBUMP_B0 = vec3( 0.816496580927726,  0.0,               0.577350269189626);
const vec3 SSBUMP_B1 = vec3(-0.408248290463863,  0.707106781186548, 0.577350269189626);
const vec3 SSBUMP_B2 = vec3(-0.408248290463863, -0.707106781186548, 0.577350269189626);

// h at point p (texels).
float relief_h(sampler2D heightMap, vec2 size, vec2 p) {
    return textureLod(heightMap, (p + 0.5) / size, 0.0).r;
}

// Where the view ray that crosses the polygon at p meets the relief.
// view: unit vector towards the viewer, tangent space, view.z > 0.
// The ray runs down from z = depth along -view; it is tested at layers a
// horizontal half texel apart at most (at least 1, at most 1024), and the
// crossing is placed on the line between the last layer above the surface
// and the first under it (parallax occlusion mapping's secant).
vec2 relief_hit(sampler2D heightMap, vec2 size, vec2 p, vec3 view, float depth) {
    float reach = depth * length(view.xy) / view.z;  // horizontal run through the relief
    float layers = clamp(ceil(2.0 * reach), 1.0, 1024.0);
    float dz = depth / layers;
    vec2 dp = -view.xy / view.z * dz;
    float z = depth;
    float above = z - depth * relief_h(heightMap, size, p);
    if (above <= 0.0) return p;
    for (int i = 0; i < int(layers); i++) {
        vec2 np = p + dp;
        float nz = z - dz;
        float below = nz - depth * relief_h(heightMap, size, np);
        if (below <= 0.0) return p + above / (above - below) * dp;
        p = np;
        z = nz;
        above = below;
    }
    return p;
}

// Static light: Source's three lightmap colours weighted by the ssbump.
vec3 ssbump_static(vec3 s, vec3 lightmap0, vec3 lightmap1, vec3 lightmap2) {
    return s.x * lightmap0 + s.y * lightmap1 + s.z * lightmap2;
}

// A dynamic light l (unit, towards it): projected on the basis and weighted
// by the ssbump, sat(sum_c s_c (l.B_c)), as Source's ssbump flashlight; on an
// unshadowed texel this is N.l, and each lobe the relief shadows takes its
// share of the light away.
float ssbump_dynamic(vec3 s, vec3 l) {
    vec3 lb = vec3(dot(l, SSBUMP_B0), dot(l, SSBUMP_B1), dot(l, SSBUMP_B2));
    return clamp(dot(s, lb), 0.0, 1.0);
}

// The paper's normal for the highlight: the basis weighted by the ssbump.
vec3 ssbump_bent_normal(vec3 s) {
    vec3 b = s.x * SSBUMP_B0 + s.y * SSBUMP_B1 + s.z * SSBUMP_B2;
    float len = length(b);
    return len > 0.0 ? b / len : vec3(0.0, 0.0, 1.0);
}

// Blinn-Phong of exponent k from a light d, seen from view, on normal n;
// nothing where the light is behind n.
float ssbump_specular(vec3 n, vec3 d, vec3 view, float k) {
    if (dot(n, d) <= 0.0) return 0.0;
    float nh = dot(n, normalize(d + view));
    return nh > 0.0 ? pow(nh, k) : 0.0;
}

// One fragment, all of it: the relief met, then the ssbump read there and
// lit by the dynamic light (light, lightColor) and the three lightmap
// colours, times the albedo, plus the highlight of every light (the three
// lightmaps shine along B_c) when specularExponent > 0.
vec3 ssbump_relief_shade(sampler2D heightMap, sampler2D ssbumpMap, vec2 size, vec2 p,
                         vec3 view, float depth, vec3 light, vec3 lightColor,
                         vec3 lightmap0, vec3 lightmap1, vec3 lightmap2, vec3 albedo,
                         float specularExponent, float specularStrength) {
    vec2 hit = relief_hit(heightMap, size, p, view, depth);
    vec3 s = textureLod(ssbumpMap, (hit + 0.5) / size, 0.0).rgb;
    vec3 diffuse = ssbump_static(s, lightmap0, lightmap1, lightmap2) +
                   ssbump_dynamic(s, light) * lightColor;
    vec3 rgb = albedo * diffuse;
    if (specularExponent > 0.0) {
        vec3 n = ssbump_bent_normal(s);
        rgb += specularStrength * (lightColor * ssbump_specular(n, light, view, specularExponent) +
                                   lightmap0 * ssbump_specular(n, SSBUMP_B0, view, specularExponent) +
                                   lightmap1 * ssbump_specular(n, SSBUMP_B1, view, specularExponent) +
                                   lightmap2 * ssbump_specular(n, SSBUMP_B2, view, specularExponent));
    }
    return rgb;
}
