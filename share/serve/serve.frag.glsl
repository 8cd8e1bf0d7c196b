// serve.frag.glsl: the fragment shader of `bumpbake serve`'s page. The page
// puts "#version 300 es", the precisions and shaders/ssbump_relief.glsl (the
// shader functions `bumpbake render` evaluates on the CPU) before it, so the
// ssbump is lit here by the same formulas as there (docs/commands/render.md,
// "Formulas"): the dynamic light sat(sum_c s_c (l.B_c)) on the ssbump,
// max(0, N.l) on the normal map, times ao in "normal x ao"; relief is
// relief_hit seen from a camera as `render --view AZ,EL --relief`, the
// ssbump met lit by the same light (ssbump_relief_shade's diffuse term
// with no lightmaps); the lit modes are times render's --albedo A and
// --light-color C, as render's output A (dynamic) C is. The basis directions B_c are the bake's own (a
// uniform): Half-Life 2's are ssbump_relief.glsl's SSBUMP_B0..B2, and a
// bake with --basis FILE of 3 other directions is lit with those; a basis
// of more than 3 does not fit the page's ssbump texture, whose lit modes
// the page then turns off.

uniform sampler2D uSsbumpAo;     // ssbump s_0..s_2 in RGB, ao in A
uniform sampler2D uNormalHeight; // (N + 1) / 2 in RGB, the smoothed height in A
uniform sampler2D uBent;         // (Nb + 1) / 2
uniform sampler2D uWeights;      // basis weights
uniform sampler2D uHeight;       // the smoothed height in R (for the relief)
uniform sampler2D uAlbedo;       // render's --albedo, RGB (grey: R = G = B)
uniform vec2 uSize;              // the maps' size in texels
uniform vec2 uCanvas;            // the drawing buffer's size in pixels
uniform vec2 uExtent;            // the maps shown: uSize, or twice it tiled 2 x 2
uniform float uZoom;             // drawing buffer pixels a texel
uniform vec2 uCenter;            // the point of the maps (texels) at the picture's centre
uniform int uMode;               // 0 ssbump lit, 1 normal lit, 2 normal x ao lit, 3 ao,
                                 // 4 bent normal, 5 weights, 6 ssbump map, 7 height, 8 relief
uniform vec3 uLight;             // towards the light, tangent frame (+y down)
uniform vec3 uLightColor;        // render's --light-color C (1, 1, 1 where nothing is lit)
uniform float uUseAlbedo;        // 1: the lit modes are times the albedo A
uniform float uNormalYUp;        // 1: the maps were baked with --normal-y up
uniform vec3 uView;              // towards the camera (relief)
uniform vec2 uRight, uToward;    // the screen's right and the way to the camera, on the plane
uniform float uStretch;          // 1 / sin(view elevation)
uniform float uDepth;            // the relief's depth in texels: the bake's --scale
uniform vec3 uBasis[3];          // the bake's basis directions B_0..B_2 (tangent frame, +y down)
out vec4 fragColor;

vec3 decode_vector(vec3 c) {
    vec3 n = c * 2.0 - 1.0;
    if (uNormalYUp > 0.5) n.y = -n.y;
    float len = length(n);
    return len > 0.0 ? n / len : vec3(0.0, 0.0, 1.0);
}

// ssbump_dynamic in the bake's basis: sat(sum_c s_c (l.B_c)).
float ssbump_lit(vec3 s, vec3 l) {
    vec3 lb = vec3(dot(l, uBasis[0]), dot(l, uBasis[1]), dot(l, uBasis[2]));
    return clamp(dot(s, lb), 0.0, 1.0);
}

void main() {
    // the pixel's point on the (tiled) maps, texels, y down; texel (i, j) at
    // (i, j); fitted, uCenter is the extent's middle and uZoom canvas / extent
    vec2 pixel = vec2(gl_FragCoord.x, uCanvas.y - gl_FragCoord.y);
    vec2 extent = uExtent;
    vec2 p = uCenter + (pixel - 0.5 * uCanvas) / uZoom - 0.5;
    vec2 uv = (p + 0.5) / uSize;
    vec3 albedo = uUseAlbedo > 0.5 ? textureLod(uAlbedo, uv, 0.0).rgb : vec3(1.0);
    vec3 rgb;
    if (uMode == 8) {
        // render's view_pixel: the picture of the tiled maps seen by the
        // camera, its pixel (i, j) at the point p = (i, j)
        float si = p.x - 0.5 * extent.x, sj = (p.y - 0.5 * extent.y) * uStretch;
        vec2 point = 0.5 * extent + si * uRight + sj * uToward;
        vec2 hit = relief_hit(uHeight, uSize, point, uView, uDepth);
        if (uUseAlbedo > 0.5) albedo = textureLod(uAlbedo, (hit + 0.5) / uSize, 0.0).rgb;
        rgb = vec3(ssbump_lit(textureLod(uSsbumpAo, (hit + 0.5) / uSize, 0.0).rgb, uLight));
    } else if (uMode == 0) {
        vec3 s = textureLod(uSsbumpAo, uv, 0.0).rgb;
        rgb = vec3(ssbump_lit(s, uLight));
    } else if (uMode == 1 || uMode == 2) {
        vec3 n = decode_vector(textureLod(uNormalHeight, uv, 0.0).rgb);
        float lit = max(0.0, dot(n, uLight));
        if (uMode == 2) lit *= textureLod(uSsbumpAo, uv, 0.0).a;
        rgb = vec3(lit);
    } else if (uMode == 3) {
        rgb = vec3(textureLod(uSsbumpAo, uv, 0.0).a);
    } else if (uMode == 4) {
        rgb = textureLod(uBent, uv, 0.0).rgb;
    } else if (uMode == 5) {
        rgb = textureLod(uWeights, uv, 0.0).rgb;
    } else if (uMode == 6) {
        rgb = textureLod(uSsbumpAo, uv, 0.0).rgb;
    } else {
        rgb = vec3(textureLod(uHeight, uv, 0.0).r);
    }
    // render's output A * light * C in the lit modes (uLightColor is 1 and
    // albedo 1 in the others); linear values written as they are, as
    // `bumpbake render` writes a PNG
    if (uMode <= 2 || uMode == 8) rgb *= albedo * uLightColor;
    fragColor = vec4(clamp(rgb, 0.0, 1.0), 1.0);
}
