#version 460
#extension GL_GOOGLE_include_directive : require
// The area trace of a spot or point light (area_trace.glsl).
#define LOCAL_LIGHT 1
#include "area_trace.glsl"
