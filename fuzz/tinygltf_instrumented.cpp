// tinygltf's implementation compiled with the fuzzer's coverage and sanitizers (Debian ships it as
// an uninstrumented shared library, which would leave the fuzzer blind inside the JSON parser).
// Same header, same macros as Debian's build, so both copies agree on every type.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
