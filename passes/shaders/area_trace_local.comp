#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// The area trace of a spot or point light (area_trace.glsl).
#define LOCAL_LIGHT 1
#include "area_trace.glsl"
