#define FRAG 1
#include "list_resolve.glsl"
