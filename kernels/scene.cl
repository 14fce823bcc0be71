/* The device's view of the scene, and the surface point a ray found. */
#ifndef MCRT_SCENE_CL
#define MCRT_SCENE_CL

#include "bvh_traverse.cl"
#include "lights.cl"

/* The uniform environment (DESIGN.md "Radiometric contract"): the ambient estimators' sky, or,
 * with --sky and a direct or path estimator, a light at infinity beside the area lights. */
typedef struct {
    float3 sky;        /* radiance of the uniform sky */
    float ao_distance; /* occlusion range; 0 = unbounded */
    float sky_pmf;     /* probability that the light strategies choose the sky light; 0: the sky
                          is no light (light_sampling.cl) */
} Environment;

typedef struct TraceMemo TraceMemo;

typedef struct {
    global const Bvh4Node* nodes;
    global const TrianglePacket* packets;     /* the leaves' triangles, for ray queries */
    global const TriangleInfo* triangle_info; /* per packet lane: material, light */
    global const Material* materials;
    LightSet lights;
    Environment env;
    TraceMemo* memo; /* the last ray of trace_from, for the path's continuation; 0: none kept */
} SceneView;

/* A surface point seen along a ray. */
typedef struct {
    float3 p;   /* from barycentrics, not from o + t·d (Wächter & Binder 2019) */
    float3 n;   /* unit geometric normal, flipped toward the incoming ray */
    float3 wo;  /* unit, toward where the ray came from */
    bool front; /* the ray arrived on the counter-clockwise (front) side */
    uint light; /* index of its Light plus one; 0 when it is not a light */
    Material material;
} SurfacePoint;

inline SurfacePoint surface_point(const SceneView* scene, const Ray* r, const Hit* hit) {
    /* The vertices from the hit's packet lane: coordinate a of vertex k at v[3k + a].lane. */
    uint lane = hit->lane % MCRT_PACKET_WIDTH;
    global const float* v =
        (global const float*)scene->packets[hit->lane / MCRT_PACKET_WIDTH].v + lane;
    float3 p0 = (float3)(v[0], v[4], v[8]);
    float3 e1 = (float3)(v[12], v[16], v[20]) - p0, e2 = (float3)(v[24], v[28], v[32]) - p0;
    TriangleInfo info = scene->triangle_info[hit->lane];
    SurfacePoint sp;
    sp.p = p0 + hit->b1 * e1 + hit->b2 * e2;
    float3 ng = normalize(cross(e1, e2));
    sp.front = dot(ng, r->dir) < 0.0f;
    sp.n = sp.front ? ng : -ng;
    sp.wo = -normalize(r->dir);
    sp.light = info.light;
    sp.material = scene->materials[info.material];
    return sp;
}

/* The last ray trace_from traced and what it found: when an estimator's BSDF or hemisphere
 * direction is also the path's continuation (path.cl), the path takes the surface from here
 * instead of tracing the same ray again. */
struct TraceMemo {
    float3 origin, wi;
    SurfacePoint seen;
    bool hit;
    bool valid;
};

/* Radiance the surface emits toward the viewer: front face only unless double-sided. */
inline float3 emitted_radiance(const SurfacePoint* sp) {
    bool emits = sp->front || (sp->material.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    return emits ? sp->material.Le.xyz : (float3)(0.0f);
}

/* Radiance that a ray leaving the scene sees: the sky when it is a light, else black. */
inline float3 environment_radiance(const SceneView* scene) {
    return scene->env.sky_pmf > 0.0f ? scene->env.sky : (float3)(0.0f);
}

/* True if nothing blocks the segment between the offset origins of a and b; na and nb are the
 * geometric normals on the sides the segment leaves a and reaches b. */
inline bool visible(const SceneView* scene, float3 a, float3 na, float3 b, float3 nb) {
    float3 o = offset_ray_origin(a, na);
    float3 target = offset_ray_origin(b, nb);
    Ray shadow = make_ray(o, target - o);
    return !bvh_any_hit(scene->nodes, scene->packets, &shadow, 1.0f);
}

/* The first surface along direction wi (unit, world) from sp, offset off its surface; false
 * when the ray leaves the scene. Counts the ray in *rays. */
inline bool trace_from(const SceneView* scene, const SurfacePoint* sp, float3 wi, uint* rays,
                       SurfacePoint* seen) {
    *rays += 1u;
    Ray r = make_ray(offset_ray_origin(sp->p, sp->n), wi);
    Hit hit = bvh_closest_hit(scene->nodes, scene->packets, &r, MAXFLOAT);
    bool found = hit.lane != MCRT_NO_HIT;
    if (found) *seen = surface_point(scene, &r, &hit);
    if (scene->memo) {
        scene->memo->origin = r.org;
        scene->memo->wi = wi;
        scene->memo->hit = found;
        if (found) scene->memo->seen = *seen;
        scene->memo->valid = true;
    }
    return found;
}

/* True if the ray from sp along wi (unit, world) leaves the scene within t_max (MAXFLOAT:
 * unbounded). Counts the ray in *rays. */
inline bool escapes(const SceneView* scene, const SurfacePoint* sp, float3 wi, float t_max,
                    uint* rays) {
    *rays += 1u;
    Ray r = make_ray(offset_ray_origin(sp->p, sp->n), wi);
    return !bvh_any_hit(scene->nodes, scene->packets, &r, t_max);
}

#endif
