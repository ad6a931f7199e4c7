#version 330 core
// Linear radiance to the display: exposure, then the sRGB curve of render/film/tonemap.h, so a
// capture equals the PNG the render core writes. view 1 shows the texture as an error or variance
// map instead: log10 from 1e-4 (black) through blue, red and yellow to 1 (white).
in vec2 uv;
out vec4 colour;
uniform sampler2D image;
uniform float exposureScale;
uniform int view;

float toSrgb(float x) {
  if (!(x > 0.0)) return 0.0;
  if (x >= 1.0) return 1.0;
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

vec3 ramp(float value) {
  float t = value > 0.0 ? clamp((log(value) / log(10.0) + 4.0) / 4.0, 0.0, 1.0) : 0.0;
  float x = t * 4.0;
  if (x < 1.0) return mix(vec3(0, 0, 0), vec3(0, 0, 1), x);
  if (x < 2.0) return mix(vec3(0, 0, 1), vec3(1, 0, 0), x - 1.0);
  if (x < 3.0) return mix(vec3(1, 0, 0), vec3(1, 1, 0), x - 2.0);
  return mix(vec3(1, 1, 0), vec3(1, 1, 1), x - 3.0);
}

void main() {
  vec3 c = texture(image, uv).rgb;
  if (view == 1) {
    colour = vec4(ramp(c.r), 1.0);
  } else {
    c *= exposureScale;
    colour = vec4(toSrgb(c.r), toSrgb(c.g), toSrgb(c.b), 1.0);
  }
}
