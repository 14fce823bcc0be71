/* Orthonormal shading frames: local z is the normal. */
#ifndef MCRT_FRAME_CL
#define MCRT_FRAME_CL

/* Right-handed orthonormal basis: cross(t, b) = n. */
typedef struct {
    float3 t, b, n;
} Frame;

/* Basis from a unit normal, branchless and continuous except at n.z = 0 with n.z's sign
 * (Duff et al. 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1), listing 3). */
inline Frame frame_from_normal(float3 n) {
    float sign = copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    Frame f;
    f.t = (float3)(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.b = (float3)(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}

/* Local coordinates (along t, b, n) to world. (`local` is an OpenCL keyword.) */
inline float3 frame_to_world(const Frame* f, float3 v) {
    return v.x * f->t + v.y * f->b + v.z * f->n;
}

/* World vector to local coordinates (along t, b, n). */
inline float3 frame_to_local(const Frame* f, float3 world) {
    return (float3)(dot(world, f->t), dot(world, f->b), dot(world, f->n));
}

#endif
