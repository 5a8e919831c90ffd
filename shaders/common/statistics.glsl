// The timed pass (AlgorithmOptions::statistics off: every timed frame of an experiment): with
// SHADOWLAB_STATISTICS 0 a shader gathers no statistics (counters, per-pixel debug images,
// the atomics and barriers that sum them); overflow and error detection never depend on it, and
// the visibility written is the same bit for bit. Every plugin passes the define
// (statisticsDefine() in framework/algorithm/AlgorithmSupport.h); 1 when it is missing.
#ifndef SHADOWLAB_STATISTICS
#define SHADOWLAB_STATISTICS 1
#endif
