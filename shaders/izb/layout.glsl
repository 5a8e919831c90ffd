// Bindings, counters and sizes of izb (the irregular z-buffer): #defines only, for C++ and GLSL.
#define IZB_HEAD_BINDING 3     // uint[faces * grid^2]: a cell's first sample, IZB_NONE for none
#define IZB_NEXT_BINDING 4     // uint[pixels]: the next sample of the same cell
#define IZB_SAMPLE_BINDING 5   // uvec4[pixels]: the sample's ray origin x (xyz, float bits), its cell (w)
#define IZB_BLOCKED_BINDING 6  // uint[pixels]: 1 once a triangle blocks the sample's ray
#define IZB_JOB_BINDING 7      // uvec2[capacity]: (triangle, face << 24 | tile): one 8 × 8 tile of cells
#define IZB_JOB_COUNT_BINDING 8 // {jobs, groups x, groups y, groups z}: the test pass's indirect grid
#define IZB_FLAG_BINDING 9     // uint[faces * tiles]: 1 where a tile's work was lost (job list full)
#define IZB_CELL_FLAG_BINDING 10 // uint[faces * grid^2]: 1 where a cell's walk was capped
#define IZB_COUNTER_BINDING 11
#define IZB_BOUNDS_BINDING 13  // grid_fit samples: per face, the box of its samples (4 ordered words)
#define IZB_OCCUPIED_BINDING 12 // uint[faces * tiles]: 1 where a tile holds a sample (no job for the others)
#define IZB_NONE 0xFFFFFFFFu     // no sample (list end), or a sample the light does not reach
#define IZB_ON_LIGHT 0xFFFFFFFEu // a lit sample on the light itself (not listed)
// A job is one tile of IZB_TILE × IZB_TILE cells of one face, tested by a workgroup of as many
// invocations, one per cell; groups in rows of IZB_ROW.
#define IZB_TILE 8
#define IZB_ROW 32768
// Counters (words).
#define IZB_C_SAMPLES 0        // lit samples inserted
#define IZB_C_JOBS 1           // jobs asked for (more than the capacity: the rest were lost, flagged)
#define IZB_C_LOST_TILES 2     // tiles whose job did not fit
#define IZB_C_CAPPED_CELLS 3   // cells whose list walk hit walk_cap
#define IZB_C_CUT_LOOPS 4      // loops ended from outside (rule 13)
#define IZB_C_OVERFLOW_PIXELS 5 // lit pixels written shadowed for any of the three above
#define IZB_C_TESTS_LO 6       // sample-triangle tests, 64-bit (instrumented)
#define IZB_C_LIST_MAX 8       // longest cell list walked (instrumented)
#define IZB_C_CELLS 9          // non-empty cells (instrumented)
#define IZB_COUNTER_WORDS 10
