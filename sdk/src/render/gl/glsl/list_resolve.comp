#define FRAG 0
#include "list_resolve.glsl"
