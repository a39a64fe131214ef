#version 460
#extension GL_GOOGLE_include_directive : require
// The area trace of a directional light (area_trace.glsl).
#define LOCAL_LIGHT 0
#include "area_trace.glsl"
