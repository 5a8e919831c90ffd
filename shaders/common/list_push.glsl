// Pushing onto a fixed-capacity list through a 32-bit fill counter. A counter that keeps counting
// past capacity wraps after 2^32 pushes and hands out slots of live entries again, which would then
// be overwritten silently (a scene ~1,000 times a list's capacity asks for that many). So a push
// that finds the list full takes its increment back at once: the counter never exceeds capacity
// plus the pushes in flight, and every push past capacity is one the caller sees and flags.
//
//   LIST_RESERVE(counter, n, capacity, slot): reserves up to n consecutive entries; `slot` gets the
//   first, and the entries from `capacity` on were not reserved (the list is full there).
//
// The fault SHADOWLAB_FAULT_PUSH_FLOOD (tests only) gives the counter a range of capacity + 64
// instead of 2^32, so that the wrap a flood of pushes would cause comes after 64 pushes
// past capacity. (With the take-back, the counter stays within capacity + the pushes in flight:
// a few dozen on a software GL, so the short range is never reached there.)
#ifndef SHADOWLAB_FAULT_PUSH_FLOOD
#define SHADOWLAB_FAULT_PUSH_FLOOD 0
#endif

#if SHADOWLAB_FAULT_PUSH_FLOOD
#define LIST_COUNTER_RANGE(old, capacity) ((old) % ((capacity) + 64u))
#else
#define LIST_COUNTER_RANGE(old, capacity) (old)
#endif

#define LIST_RESERVE(counter, n, capacity, slot)                                              \
    {                                                                                         \
        uint inc_ = (n);                                                                      \
        slot = LIST_COUNTER_RANGE(atomicAdd(counter, inc_), capacity);                        \
        uint over_ = slot >= (capacity) ? inc_ : max(slot + inc_, (capacity)) - (capacity);   \
        if (over_ != 0u) atomicAdd(counter, 0u - over_);                                      \
    }
