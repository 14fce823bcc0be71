/* The device's view of the scene, and what a camera ray found. */
#ifndef MCRT_SCENE_CL
#define MCRT_SCENE_CL

#include "bvh_traverse.cl"
#include "lights.cl"

typedef struct {
    global const Bvh4Node* nodes;
    global const TrianglePacket* packets; /* the leaves' triangles, for ray queries */
    global const Triangle* triangles;
    global const Material* materials;
    LightSet lights;
} SceneView;

/* A surface point seen along a ray. */
typedef struct {
    float3 p;      /* from barycentrics, not from o + t·d (Wächter & Binder 2019) */
    float3 n;      /* unit geometric normal, flipped toward the incoming ray */
    bool front;    /* the ray arrived on the counter-clockwise (front) side */
    uint light;    /* index of its Light plus one; 0 when it is not a light */
    Material material;
} SurfacePoint;

inline SurfacePoint surface_point(const SceneView* scene, const Ray* r, const Hit* hit) {
    Triangle tri = scene->triangles[hit->triangle];
    float3 p0 = tri.p0.xyz, e1 = tri.p1.xyz - p0, e2 = tri.p2.xyz - p0;
    SurfacePoint sp;
    sp.p = p0 + hit->b1 * e1 + hit->b2 * e2;
    float3 ng = normalize(cross(e1, e2));
    sp.front = dot(ng, r->dir) < 0.0f;
    sp.n = sp.front ? ng : -ng;
    sp.light = as_uint(tri.p2.w);
    sp.material = scene->materials[as_uint(tri.p0.w)];
    return sp;
}

/* Radiance the surface emits toward the viewer: front face only unless double-sided. */
inline float3 emitted_radiance(const SurfacePoint* sp) {
    bool emits = sp->front || (sp->material.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    return emits ? sp->material.Le.xyz : (float3)(0.0f);
}

/* True if nothing blocks the segment between the offset origins of a and b. */
inline bool visible(const SceneView* scene, float3 a, float3 na, float3 b, float3 nb) {
    float3 o = offset_ray_origin(a, na);
    float3 target = offset_ray_origin(b, nb);
    Ray shadow = make_ray(o, target - o);
    return !bvh_any_hit(scene->nodes, scene->packets, &shadow, 1.0f);
}

#endif
