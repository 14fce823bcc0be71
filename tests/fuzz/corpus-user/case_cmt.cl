/* float3 estimate(void) */
float3 f(void) { return 0; }
