// Tests only: SHADOWLAB_FAULT_LOOP_BUDGET=N makes every loop that starts its body with
// FAULT_LOOP_STEP() end once the invocation has run N passes of such loops in all, as llvmpipe's
// and lavapipe's loop limit does (one counter shared by every loop of an invocation: the loop
// simply exits; docs/architecture.md, rule 13). Each loop must then notice that it was cut.
#ifndef SHADOWLAB_FAULT_LOOP_BUDGET
#define SHADOWLAB_FAULT_LOOP_BUDGET 0
#endif
#if SHADOWLAB_FAULT_LOOP_BUDGET
uint gFaultLoopPasses = 0u;
#define FAULT_LOOP_STEP() if (++gFaultLoopPasses > uint(SHADOWLAB_FAULT_LOOP_BUDGET)) break;
#else
#define FAULT_LOOP_STEP()
#endif
