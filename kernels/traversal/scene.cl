/* The device's view of the scene, and the surface point a ray found. */
#ifndef MCRT_SCENE_CL
#define MCRT_SCENE_CL

#include "bvh_traverse.cl"
#include "lights.cl"
#if defined(MCRT_ENVIRONMENT_MAP)
#include "environment.cl"
#endif

/* The environment (DESIGN.md "Radiometric contract"): the uniform sky or, in -D
 * MCRT_ENVIRONMENT_MAP builds, the map of --env; the ambient estimators' sky, or, with a direct or
 * path estimator, a light at infinity beside the area lights. */
typedef struct {
    float3 sky;        /* radiance of the uniform sky */
    float ao_distance; /* occlusion range; 0 = unbounded */
    float sky_pmf;     /* probability that the light strategies choose the sky light, a multiple of
                          2^-24; 0: the sky is no light (light_sampling.cl) */
#if defined(MCRT_ENVIRONMENT_MAP)
    EnvironmentMapView map; /* the sky's radiance by direction, in place of `sky` */
#endif
} Environment;

typedef struct PathContinuation PathContinuation; /* api.cl */

typedef struct {
    global const Bvh4Node* nodes;
    global const TrianglePacket* packets;     /* the leaves' triangles, for ray queries */
    global const TriangleInfo* triangle_info; /* per packet lane: material, light */
    global const Material* materials;
    LightSet lights;
    Environment env;
    PathContinuation* continuation; /* where trace_bsdf_sample hands the path its BSDF sample
                                       (api.cl); 0 where no path goes on (direct lighting) */
#if defined(MCRT_TEXTURES)
    TextureView textures;
    uint* alpha_key; /* the current vertex's stochastic-transparency key (path.cl) */
#endif
} SceneView;

/* A surface point seen along a ray. */
typedef struct {
    float3 p;       /* from barycentrics, not from o + t·d (PBRT 4th ed. sec. 6.8.5) */
    float3 p_error; /* per-component bound on p's distance from its triangle (geometry.cl) */
    float3 n;       /* unit shading normal, on the incoming ray's side: the geometric normal,
                       or where a normal texture bends it, the bent one (textured builds) */
    float3 ng;      /* unit geometric normal, flipped toward the incoming ray: rays leave the
                       surface on its side, and no light arrives from behind it */
    float3 wo;  /* unit, toward where the ray came from */
    bool front; /* the ray arrived on the counter-clockwise (front) side */
    uint light; /* index of its Light plus one; 0 when it is not a light */
    uint lane;  /* its triangle's packet lane, which rays leaving it skip; MCRT_NO_HIT: none */
    Material material;
} SurfacePoint;

#if defined(MCRT_TEXTURES)
/* n turned toward ng in their plane just enough that the mirror direction of wo about it is
 * t = min(0.9 cosθ_o, 0.01) above the surface (unchanged where it already is): Cycles'
 * ensure_valid_specular_reflection (Blender, intern/cycles/kernel/closure/bsdf_util.h). With
 * n' = sinφ·x + cosφ·ng, x the unit part of n across ng, the mirror direction's height is
 * i_x sin2φ + i_z cos2φ = a cos(2φ − ψ), (i_z, i_x) = a (cosψ, sinψ), so 2φ' = ψ + β with
 * cosβ = t/a: the root between ng and n, and n' the half vector of ng and the angle 2φ'. */
inline float3 lift_specular_reflection(float3 n, float3 ng, float3 wo) {
    float i_z = dot(wo, ng);
    float t = fmin(0.9f * i_z, 0.01f);
    if (dot(2.0f * dot(n, wo) * n - wo, ng) >= t) return n;
    float3 x = n - dot(n, ng) * ng;
    if (!(dot(x, x) > 0.0f)) return ng;
    x = normalize(x);
    float i_x = dot(wo, x);
    float a = sqrt(i_x * i_x + i_z * i_z);
    if (!(a > 0.0f)) return ng;
    float cos_b = fmin(t / a, 1.0f), sin_b = sqrt(1.0f - cos_b * cos_b);
    float cos_2phi = (i_z * cos_b - i_x * sin_b) / a, sin_2phi = (i_x * cos_b + i_z * sin_b) / a;
    return normalize((1.0f + cos_2phi) * ng + sin_2phi * x);
}

/* The bent normal of a normal texture (glTF 2.0 "normalTexture": tangent space, +Y up, x and y
 * scaled by `scale`) about the interpolated vertex normal and MikkTSpace tangent, on the side of
 * the geometric normal ng that the ray arrived on, and turned toward the viewer where the texture
 * tilts it away (else the BSDF would be black seen from there) or, for a model with a specular
 * lobe, past where its mirror direction leaves the surface; ng where the frame degenerates. */
inline float3 bent_normal(const TextureView* tv, global const MaterialTextures* mt, uint lane,
                          float b1, float b2, float4 uv, const SurfacePoint* sp) {
    global const TriangleSurface* s = tv->surfaces + lane;
    float b0 = 1.0f - b1 - b2;
    float3 n = (b0 * s->normal[0] + b1 * s->normal[1] + b2 * s->normal[2]).xyz;
    float4 t4 = b0 * s->tangent[0] + b1 * s->tangent[1] + b2 * s->tangent[2];
    float3 t = t4.xyz - n * dot(n, t4.xyz);
    if (!(dot(n, n) > 0.0f) || !(dot(t, t) > 0.0f)) return sp->ng;
    n = normalize(n);
    t = normalize(t);
    float3 b = cross(n, t) * (t4.w < 0.0f ? -1.0f : 1.0f);
    float3 c = texture_lookup(tv, &mt->normal, uv).xyz * 2.0f - 1.0f;
    /* The texture's +u' and up (−v') directions in the frame of the untransformed coordinates:
     * T' = cos·T − sin·B, B' = sin·T + cos·B for KHR_texture_transform's rotation. */
    float x = mt->normal_cos * c.x + mt->normal_sin * c.y;
    float y = mt->normal_cos * c.y - mt->normal_sin * c.x;
    float3 ns = normalize((x * mt->normal_scale) * t + (y * mt->normal_scale) * b + c.z * n);
    if (!sp->front) ns = -ns;
    if (!(dot(ns, sp->ng) > 0.0f)) return sp->ng;
    /* A specular lobe's mirror direction kept above the surface, else the rim of a bump that the
     * texture tilts past 45° from the view reflects into the surface and renders black. */
    if (sp->material.type != MATERIAL_LAMBERTIAN)
        return lift_specular_reflection(ns, sp->ng, sp->wo);
    /* Lambertian: turned toward wo until wo is at least 0.01 above it. */
    float c_o = dot(ns, sp->wo);
    if (c_o < 0.01f) ns = normalize(ns + (0.01f - c_o) * sp->wo);
    return ns;
}

/* The material's textures evaluated at the hit (MaterialTextures): base colour and alpha,
 * metallic and roughness, emission, the shading normal, transmission. */
inline void apply_textures(const SceneView* scene, uint material, uint lane, float b1, float b2,
                           SurfacePoint* sp) {
    const TextureView* tv = &scene->textures;
    global const MaterialTextures* mt = material_textures(tv, material);
    float4 uv = surface_uv(tv, lane, b1, b2);
    if (texture_slot_used(&mt->base_color))
        sp->material.base_color *= texture_lookup(tv, &mt->base_color, uv);
    if (texture_slot_used(&mt->metallic_roughness)) {
        float4 c = texture_lookup(tv, &mt->metallic_roughness, uv);
        sp->material.metallic *= c.z;
        float roughness = mt->roughness * c.y;
        sp->material.alpha = fmax(roughness * roughness, MCRT_ALPHA_MIN);
    }
    if (texture_slot_used(&mt->emissive))
        sp->material.emission.xyz *= texture_lookup(tv, &mt->emissive, uv).xyz;
    if (texture_slot_used(&mt->normal)) sp->n = bent_normal(tv, mt, lane, b1, b2, uv, sp);
#if defined(MCRT_TRANSMISSION)
    /* KHR_materials_transmission: transmissionTexture's R channel × transmissionFactor. */
    if (texture_slot_used(&mt->transmission))
        sp->material.transmission *= texture_lookup(tv, &mt->transmission, uv).x;
#endif
}

/* The alpha test of a ray query: the vertex's key mixed with the ray's direction, so that each
 * query (the camera ray, each shadow ray, each continuation) decides a blended surface on its
 * own number. */
inline AlphaTest ray_alpha_test(const SceneView* scene, const Ray* r) {
    AlphaTest at;
    at.textures = scene->textures;
    at.triangle_info = scene->triangle_info;
    at.materials = scene->materials;
    uint3 d = as_uint3(r->dir);
    at.key = alpha_hash(*scene->alpha_key ^ alpha_hash(d.x ^ alpha_hash(d.y ^ alpha_hash(d.z))));
    return at;
}
#else
inline AlphaTest ray_alpha_test(const SceneView* scene, const Ray* r) {
    AlphaTest at;
    at.unused = 0u;
    return at;
}
#endif

inline SurfacePoint surface_point(const SceneView* scene, const Ray* r, const Hit* hit) {
    /* The vertices from the hit's packet lane: coordinate a of vertex k at v[3k + a].lane. */
    uint lane = hit->lane % MCRT_PACKET_WIDTH;
    global const float* v =
        (global const float*)scene->packets[hit->lane / MCRT_PACKET_WIDTH].v + lane;
    float3 p0 = (float3)(v[0], v[4], v[8]), p1 = (float3)(v[12], v[16], v[20]),
           p2 = (float3)(v[24], v[28], v[32]);
    float3 e1 = p1 - p0, e2 = p2 - p0;
    TriangleInfo info = scene->triangle_info[hit->lane];
    SurfacePoint sp;
    float3 b1_e1 = hit->b1 * e1, b2_e2 = hit->b2 * e2;
    sp.p = p0 + b1_e1 + b2_e2;
    sp.p_error = interpolation_error(p0, b1_e1, b2_e2);
#ifdef MCRT_HAVE_FP64
    /* Where the ray meets the triangle's plane, in double, rounded to float toward the ray's
     * origin: within an ulp of the exact point along the plane too, where the barycentric form
     * is off by the vertices' rounding (6e-5 m on a 2 km floor), and on the ray's side of any
     * surface that the ulp straddles, as the exact point is (it is the closest hit). Rounded
     * to nearest, a floor point a fraction of an ulp from a wall's base would land on the wall
     * and see past it. The double arithmetic's own error (a few 2^-53 of the magnitudes it
     * sums) is added to the bound. */
    double3 o = convert_double3(r->org), dir = convert_double3(r->dir);
    double3 d0 = convert_double3(p0);
    double3 nd = mcrt_cross_double3(convert_double3(p1) - d0, convert_double3(p2) - d0);
    double t = mcrt_dot_double3(d0 - o, nd) / mcrt_dot_double3(dir, nd);
    if (isfinite(t) && t > 0.0) {
        double3 pd = o + t * dir;
        /* Rounded to nearest, then one float back toward the origin where that went past pd
         * (cheaper than a directed conversion, which PoCL emulates). */
        float3 pf = convert_float3(pd);
        long3 past = (convert_double3(pf) - pd) * dir > (double3)(0.0);
        sp.p = select(pf, float_step(pf, -r->dir), convert_int3(past));
        /* |o + t·d| ≤ |o| + |t·d| ≤ 2|o| + |p|. */
        sp.p_error = 0x1.0p-23f * fabs(sp.p) +
                     0x1.0p-47f * (fabs(r->org) + fabs(sp.p) + fabs(p0));
    }
#endif
    sp.lane = hit->lane;
    float3 ng = normalize(cross(e1, e2));
    sp.front = dot(ng, r->dir) < 0.0f;
    sp.n = sp.front ? ng : -ng;
    sp.ng = sp.n;
    sp.wo = -normalize(r->dir);
    sp.light = info.light;
    sp.material = scene->materials[info.material];
#if defined(MCRT_TEXTURES)
    if (sp.material.flags & MATERIAL_TEXTURED)
        apply_textures(scene, info.material, hit->lane, hit->b1, hit->b2, &sp);
#endif
    return sp;
}

/* Radiance the surface emits toward the viewer: front face only unless double-sided. */
inline float3 emitted_radiance(const SurfacePoint* sp) {
    bool emits = sp->front || (sp->material.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    return emits ? sp->material.emission.xyz : (float3)(0.0f);
}

/* Radiance that a ray leaving the scene along wi (unit, world) sees: the environment map's texel
 * there (-D MCRT_ENVIRONMENT_MAP), else the uniform sky when it is a light, else black. */
inline float3 environment_radiance(const SceneView* scene, float3 wi) {
#if defined(MCRT_ENVIRONMENT_MAP)
    return environment_map_radiance(&scene->env.map, wi);
#else
    return scene->env.sky_pmf > 0.0f ? scene->env.sky : (float3)(0.0f);
#endif
}

/* The origin of rays leaving sp on the side of its geometric normal (geometry.cl). */
inline float3 spawn_origin(const SurfacePoint* sp) {
    return offset_ray_origin(sp->p, sp->p_error, sp->ng);
}

/* True if nothing blocks the segment from sp to the point y, whose per-component error bound
 * is y_error (zero for a point known exactly) and n_y the unit geometric normal of y's surface
 * on the side the segment reaches. Both ends are moved off their surfaces by their bounds
 * (PBRT 4th ed. sec. 6.8.6, SpawnRayTo), sp's triangle is skipped, and a hit counts only where
 * rounding cannot have put it at either end (bvh_any_hit). Not counted in the rays. */
inline bool visible(const SceneView* scene, const SurfacePoint* sp, float3 y, float3 y_error,
                    float3 n_y) {
    float3 o = spawn_origin(sp);
    float3 target = offset_ray_origin(y, y_error, n_y);
    Ray shadow = make_ray(o, target - o);
    AlphaTest at = ray_alpha_test(scene, &shadow);
    return !bvh_any_hit(scene->nodes, scene->packets, &shadow, 1.0f, sp->lane, &at);
}

/* The first surface along direction wi (unit, world) from sp, leaving its surface as visible
 * does (its triangle skipped, the origin off its plane by its error bound, on wi's side); false
 * when the ray leaves the scene. Counts the ray in *rays. */
inline bool trace_from(const SceneView* scene, const SurfacePoint* sp, float3 wi, uint* rays,
                       SurfacePoint* seen) {
    *rays += 1u;
#if defined(MCRT_TRANSMISSION)
    /* A transmitted direction leaves on the far side, beyond the error bound there. */
    float3 o = dot(wi, sp->ng) < 0.0f ? offset_ray_origin(sp->p, sp->p_error, -sp->ng)
                                      : spawn_origin(sp);
    Ray r = make_ray(o, wi);
#else
    Ray r = make_ray(spawn_origin(sp), wi);
#endif
    AlphaTest at = ray_alpha_test(scene, &r);
    Hit hit = bvh_closest_hit(scene->nodes, scene->packets, &r, MAXFLOAT, sp->lane, &at);
    bool found = hit.lane != MCRT_NO_HIT;
    if (found) *seen = surface_point(scene, &r, &hit);
    return found;
}

/* True if the ray from sp along wi (unit, world) leaves the scene within t_max (MAXFLOAT:
 * unbounded). Counts the ray in *rays. A direction behind the geometric surface (a bent normal's
 * hemisphere reaches below it) does not leave: the surface itself blocks it. */
inline bool escapes(const SceneView* scene, const SurfacePoint* sp, float3 wi, float t_max,
                    uint* rays) {
    *rays += 1u;
#if defined(MCRT_TEXTURES)
    if (!(dot(wi, sp->ng) > 0.0f)) return false;
#endif
    Ray r = make_ray(spawn_origin(sp), wi);
    AlphaTest at = ray_alpha_test(scene, &r);
    return !bvh_any_hit(scene->nodes, scene->packets, &r, t_max, sp->lane, &at);
}

#endif
