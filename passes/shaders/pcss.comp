#version 460
#extension GL_GOOGLE_include_directive : require
// PCSS and the classic shadow-map test; the shrinking filter's hard edge is the shadow map's own test.
#include "pcss_main.glsl"
