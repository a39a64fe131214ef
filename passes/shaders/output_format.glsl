// The format qualifier of the image a pass's final visibility goes into: r32f (the plugin's own image or an
// R32_SFLOAT output), or r16f / r8 in the variants that write an engine's R16_SFLOAT / R8_UNORM output layer
// directly (shader_build compiles one module per value).
#ifndef OUTPUT_FORMAT
#define OUTPUT_FORMAT r32f
#endif
