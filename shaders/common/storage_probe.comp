#version 450
// Does a storage block address the whole buffer bound to it, past the context's
// GL_MAX_SHADER_STORAGE_BLOCK_SIZE? Writes a word at uIndex, reads the word the host wrote below it
// and writes it back one above: the host checks both (framework/experiment/MemoryPlan.cpp).
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Probe { uint words[]; };
uniform uint uIndex;
void main() {
    words[uIndex] = 0x5EEDu;
    words[uIndex + 1u] = words[uIndex - 1u] + 1u;
}
