#pragma once
// OpenGL 4.5 core declarations for the whole project.
//
// gl* names are macros for function pointers resolved at run time by loadGlFunctions() (generated
// from glcorearb.h by scripts/gen_gl_loader.py), which each context back end calls with its own
// GetProcAddress. OSMesa exports only part of the 4.5 API as symbols, and OSMesa and libGL both
// export gl* symbols, so linking GL functions directly would be both incomplete and fragile.
#include "GlFunctions.h"

#ifndef GL_SUBGROUP_SIZE_ARB
#define GL_SUBGROUP_SIZE_ARB 0x9532
#endif
