// Mirrors passes::bvh::BvhNode (64 bytes): an internal node of the bounding volume hierarchy over the prim
// buffer (passes::bvh), with its two children's boxes inline. A child is another internal node (its index)
// or, with BVH_LEAF set, one triangle (its index in the prim buffer). The root is node 0; a hierarchy over
// one triangle has one node whose children are both that triangle.
struct BvhNode {
    vec4 left_lo;   // xyz: the left child's box minimum; w: the left child (uint bits)
    vec4 left_hi;   // xyz: the left child's box maximum
    vec4 right_lo;  // xyz: the right child's box minimum; w: the right child (uint bits)
    vec4 right_hi;  // xyz: the right child's box maximum
};

const uint BVH_LEAF = 0x80000000u;
