#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// The area trace of a directional light (area_trace.glsl).
#define LOCAL_LIGHT 0
#include "area_trace.glsl"
