#include "framework/accel/SceneBvh.h"

namespace shadowlab::bvh {

BvhStats SceneBvh::build(const SceneGpu& scene, const BuildOptions& options, size_t limit, const std::string& owner) {
    gpu_ = BvhGpu(); // free the old trees before building the new one
    tree_ = Bvh();
    posed_.clear();
    Bvh tree = buildBvh(scene.cpu(), options);
    const GLbitfield flags = scene.dynamic() ? GL_DYNAMIC_STORAGE_BIT : 0; // refitted trees are re-uploaded
    gpu_ = uploadBvh(tree, limit, flags, owner);
    const BvhStats stats{tree.nodes.size(), tree.leaves, tree.depth, tree.sahCost};
    if (scene.dynamic()) {
        tree_ = std::move(tree);
        posed_ = scene.cpu().positions;
    }
    return stats;
}

void SceneBvh::refit(const SceneGpu& scene, StageTimer& timer) {
    timer.begin("read_scene");
    scene.readMovingPositions(posed_);
    timer.end();
    timer.begin("refit", false);
    refitBvh(tree_, posed_);
    timer.end();
    timer.begin("upload");
    gpu_.nodes.upload(tree_.nodes.data(), tree_.nodes.size() * sizeof(NodeGpu));
    gpu_.triangles.upload(tree_.triangles.data(), tree_.triangles.size() * sizeof(glm::vec4));
    timer.end();
}

} // namespace shadowlab::bvh
