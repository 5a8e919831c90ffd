#pragma once
// The loader entry point without any GL header, for context back ends whose own headers
// (GL/osmesa.h includes GL/gl.h) must not meet the loader's gl* macros.
namespace shadowlab {
/// Resolves every GL function through `getProc`; call once a context is current.
void loadGlFunctions(void* (*getProc)(const char*));
} // namespace shadowlab
