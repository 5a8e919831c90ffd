// Bindings and counter slots of the template plugin: #defines only, included by C++ and GLSL.
#define TEMPLATE_ORDER_BINDING 3
#define TEMPLATE_SAMPLE_BINDING 4
#define TEMPLATE_COUNTER_BINDING 5
#define TEMPLATE_C_PIXELS 0
#define TEMPLATE_C_TESTS_LO 1
#define TEMPLATE_C_TESTS_HI 2
#define TEMPLATE_C_CUT_LOOPS 3 // rays whose loop was ended from outside (written blocked)
#define TEMPLATE_COUNTER_WORDS 4
// A light with more samples than samples_per_dispatch takes several dispatches (SampleBatches,
// framework/algorithm/AlgorithmSupport.h); between them each traced pixel keeps its unblocked
// samples so far in the accumulation image at this image unit (R32UI; RG32UI when instrumented:
// y = triangle tests so far).
#define TEMPLATE_ACCUM_UNIT 2
