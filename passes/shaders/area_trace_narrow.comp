#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// The area trace of a directional light whose bundle is never wide (area_trace.glsl): without the samples'
// own walks.
#define LOCAL_LIGHT 0
#define SAMPLE_WALKS 0
#include "area_trace.glsl"
