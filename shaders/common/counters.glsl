// 64-bit statistics kept as two words of a uint counter array, low word at `lo`: the carry goes
// into lo + 1 (the host reads them with GpuCounters::wide()). A macro because GLSL cannot pass a
// buffer array to a function.
#define COUNTER_ADD_WIDE(counters, lo, value)                                   \
    {                                                                           \
        uint wideValue_ = (value);                                              \
        uint wideOld_ = atomicAdd(counters[lo], wideValue_);                    \
        if (wideOld_ + wideValue_ < wideOld_) atomicAdd(counters[(lo) + 1], 1u); \
    }
