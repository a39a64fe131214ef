#version 460
#extension GL_EXT_ray_tracing : require
// The peer's shadow ray reached t_max without a hit: lit.
layout(location = 0) rayPayloadInEXT float lit;

void main() {
    lit = 1.0;
}
