"""GLSL 3.30 shaders of the mesh renderer.

Lighting is done in linear RGB and written gamma-encoded (sRGB ~ gamma 2.2): a hemisphere ambient (sky above,
warm ground bounce below, in world Y), a key light from the camera's upper left, a cool fill from its right, a
view-dependent rim that separates the silhouette from the background, and a soft Blinn highlight from the key.
The light directions are set relative to the camera, so every view is lit the same way. Cloth is double-sided:
a back face is shaded with its normal flipped and a little darker, so a garment's inside reads as the inside.

The wireframe overlay draws triangle edges from barycentric coordinates (the mesh is then drawn unindexed,
three vertices per triangle, and the corner is `gl_VertexID % 3`), anti-aliased with screen-space derivatives.
"""

VERTEX = """
#version 330
uniform mat4 u_view_proj;
uniform bool u_unindexed;
in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;
out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_bary;
void main() {
    v_position = in_position;
    v_normal = in_normal;
    v_uv = in_uv;
    int corner = u_unindexed ? gl_VertexID % 3 : 0;
    v_bary = vec3(corner == 0, corner == 1, corner == 2);
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
"""

FRAGMENT = """
#version 330
uniform vec3 u_eye;
uniform vec3 u_color;          // linear RGB
uniform bool u_textured;
uniform sampler2D u_texture;   // sRGB-encoded texels
uniform bool u_flat;
uniform vec3 u_key_dir;        // world directions toward the lights (unit)
uniform vec3 u_fill_dir;
uniform float u_wire_px;       // wireframe line width in pixels, 0 = off
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_bary;
out vec4 f_color;

const vec3 SKY = vec3(0.27, 0.29, 0.33);
const vec3 GROUND = vec3(0.11, 0.095, 0.08);
const vec3 KEY = vec3(1.10, 1.05, 0.97);
const vec3 FILL = vec3(0.30, 0.33, 0.40);
const vec3 RIM = vec3(0.30, 0.32, 0.36);
const float SPECULAR = 0.10;
const float SHININESS = 28.0;
const float BACKFACE_DIM = 0.8;

void main() {
    vec3 n = u_flat ? cross(dFdx(v_position), dFdy(v_position)) : v_normal;
    n = normalize(n);
    // Flat normals from derivatives already face the viewer; smooth ones are flipped on back faces.
    if (!u_flat && !gl_FrontFacing) n = -n;
    vec3 v = normalize(u_eye - v_position);
    // A smooth normal can still point a little away from the viewer near the silhouette: bend it back.
    float nv = dot(n, v);
    if (nv < 0.0) { n = normalize(n - nv * v * 1.01); nv = dot(n, v); }

    vec3 base = u_color;
    if (u_textured) base = pow(texture(u_texture, v_uv).rgb, vec3(2.2));

    vec3 ambient = mix(GROUND, SKY, 0.5 + 0.5 * n.y);
    float key = max(dot(n, u_key_dir), 0.0);
    float fill = max(dot(n, u_fill_dir), 0.0);
    float rim = pow(1.0 - clamp(nv, 0.0, 1.0), 3.0);
    vec3 h = normalize(u_key_dir + v);
    float spec = key > 0.0 ? pow(max(dot(n, h), 0.0), SHININESS) : 0.0;

    vec3 light = ambient + KEY * key + FILL * fill + RIM * rim;
    vec3 color = base * light + KEY * SPECULAR * spec;
    if (!gl_FrontFacing) color *= BACKFACE_DIM;

    if (u_wire_px > 0.0) {
        vec3 d = fwidth(v_bary);
        vec3 a = smoothstep(d * (u_wire_px - 0.5), d * (u_wire_px + 0.5), v_bary);
        float edge = 1.0 - min(min(a.x, a.y), a.z);
        // Lines a darker shade of the surface: they read on any colour and do not drown a dense mesh.
        color = mix(color, color * 0.25, edge * 0.7);
    }
    // Soft shoulder instead of a hard clip, then gamma-encode.
    color = color / (1.0 + 0.15 * max(color - 0.85, 0.0));
    f_color = vec4(pow(clamp(color, 0.0, 1.0), vec3(1.0 / 2.2)), 1.0);
}
"""

#: A full-screen triangle with a vertical gradient, drawn first (no depth) as the background.
BACKGROUND_VERTEX = """
#version 330
out float v_t;
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    v_t = 0.5 - 0.5 * p.y;  // 0 at the top edge, 1 at the bottom
    gl_Position = vec4(p, 0.0, 1.0);
}
"""

BACKGROUND_FRAGMENT = """
#version 330
uniform vec3 u_top;     // sRGB-encoded, mixed as they are (like a 2D gradient tool)
uniform vec3 u_bottom;
in float v_t;
out vec4 f_color;
void main() {
    f_color = vec4(mix(u_top, u_bottom, clamp(v_t, 0.0, 1.0)), 1.0);
}
"""
