#version 460
#extension GL_GOOGLE_include_directive : require
// PCSS whose shrinking filter takes its hard edge from the ray-traced visibility (binding 5).
#define HARD_EDGE_FROM_RAY_TRACE
#include "pcss_main.glsl"
