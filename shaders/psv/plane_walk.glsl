// PSV's plane walks (query.comp, first pass): the stack and stackless walks decided by the tree's
// planes alone. Each stops at the first capping plane q is behind or too close to call, as the
// exact walk does, and decides there after the loop: q inside all four of the triangle's planes
// by more than the close-call margin is shadowed; anything else is a close call, and the pixel is
// listed for the exact walk (query.comp's second pass, PSV_QUERY_PASS 1), which walks it again
// from the root and decides such triangles by the reference's ray. The plane walk visits the exact
// walk's nodes up to that point and decides a shadow from the same plane values
// (psvClearlyInside), and a pixel it finds lit met no close call, so the two passes write the
// exact walk's image.
//
// Why a second pass: a SIMD back end (llvmpipe, and any GPU for a divergent branch) pays for a
// loop's body whatever few lanes take a branch of it. With the ray test, or even a list append or
// a second read of the frustum's planes, inside the walk's loops every node paid for it
// (measured: results/reference/psv_plane_walk_llvmpipe.md). Here the node loop holds what the
// paper's walk holds, and the decision runs once, after it.
//
// Include after the definitions of Query, Result, psvClearlyInside, PSV_VISITS_INTER and
// PSV_SKIPS_DEPTH.

// After a plane walk's loop: the pixel's decision at capping node `cap` (0: none), for a walk that
// ended the tree (`done`) or stopped at a capping plane; a loop left otherwise was ended from
// outside by the device (llvmpipe after 65,535 iterations in all, docs/architecture.md rule 13):
// capped, written shadowed and counted.
void psvPlaneDecision(Query Q, uint cap, bool done, inout Result r) {
    if (cap != 0u) {
        if (psvClearlyInside(Q, (cap - 1u) / PSV_NODES_PER_TRIANGLE)) r.visibility = 0.0;
        else r.deferred = true;
    } else if (!done && !r.overflow) {
        r.capped = true;
    }
    r.overflow = r.overflow || r.capped;
    if (r.overflow) { r.visibility = 0.0; r.deferred = false; }
}

#if PSV_TRAVERSAL == 0
// The stack walk (Gerhards et al. 2015, Algorithm 2), as query.comp's exact stack walk.
Result psvPlaneWalk(Query Q) {
    Result r = Result(1.0, 0u, 0u, 0u, false, false, false);
    uint stack[PSV_STACK_SIZE];
    int sp = 0;
    uint node = psvNode(0u).pos, cap = 0u;
    bool done = false;
    // Pushing onto a full stack would drop a subtree that may hold the occluder: stop and report.
#define PSV_PUSH(child) { if (sp == PSV_STACK_SIZE) { r.overflow = true; break; } stack[sp++] = (child); }
    while (true) {
        if (node == 0u) {
            if (sp == 0) { done = true; break; }
            node = stack[--sp];
        }
        ++r.visited;
        PsvNode n = psvNode(node);
        float s = psvSigned(n.plane, Q.q);
        if (node % PSV_NODES_PER_TRIANGLE != 0u) { // shadow plane
            uint next = s <= psvCloseCall ? node + 1u : n.pos;
            if (PSV_VISITS_INTER(Q, n, s)) {
                if (next == 0u) next = n.inter;
                else PSV_PUSH(n.inter);
            }
            node = next;
            continue;
        }
        if (PSV_SKIPS_DEPTH(Q, n)) { node = 0u; continue; }
        if (s <= psvCloseCall) { cap = node; break; }
        if (n.inter != 0u) PSV_PUSH(n.inter);
        node = n.pos;
    }
#undef PSV_PUSH
    psvPlaneDecision(Q, cap, done, r);
    return r;
}
#elif PSV_TRAVERSAL == 1
// The stackless walk (Mora et al. 2016), as psvWalkStackless in query.comp over the whole tree.
Result psvPlaneWalk(Query Q) {
    Result r = Result(1.0, 0u, 0u, 1u, false, false, false);
    uint node = psvNode(0u).pos, cap = 0u;
    bool second = false, done = false;
    uint budget = psvEscapeBudget();
    while (true) {
        if (node == 0u) { done = true; break; } // the whole tree walked (or the escape cap: capped)
        ++r.visited;
        PsvNode n = psvNode(node);
        float s = psvSigned(n.plane, Q.q);
        uint side; // the child on q's side of the plane (0: none)
        if (node % PSV_NODES_PER_TRIANGLE != 0u) { // shadow plane
            side = s <= psvCloseCall ? node + 1u : n.pos;
            if (!second && PSV_VISITS_INTER(Q, n, s)) { node = n.inter; continue; }
        } else { // capping plane
            if (!second && PSV_SKIPS_DEPTH(Q, n)) side = 0u;
            else if (!second && s <= psvCloseCall) { cap = node; break; }
            else side = !second && n.inter != 0u ? n.inter : n.pos;
        }
        // The next node: `side`, or where it is none the escape of this node's triangle; past the
        // escape cap the root's owner (0), capped (data flow into the jump, as in psvWalkStackless).
        second = side == 0u;
        budget -= second ? 1u : 0u;
        bool over = budget == 0u;
        r.capped = r.capped || over;
        node = over ? 0u : (second ? psvEscape((node - 1u) / PSV_NODES_PER_TRIANGLE) : side);
    }
    psvPlaneDecision(Q, cap, done, r);
    return r;
}
#endif
