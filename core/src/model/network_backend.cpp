#include "fignet/model/network_backend.h"

#include <algorithm>

#include "parallel/parallel_for.h"

namespace fignet {

double NetworkBackend::forward_backward(const float* params, const Normalizers& normalizers,
                                        const Graph& graph, float* grads,
                                        const LossGradient& loss) {
  const ConstMatrixView output = forward(params, normalizers, graph, /*keep_for_backward=*/true);
  MatrixView d_output = d_output_.view(output.rows(), 3);
  const double value = loss(0, output, d_output);
  backward(params, grads, graph, d_output);
  return value;
}

namespace {

// The CPU backend runs a batch of several scenes as chunks of whole scenes, about
// kChunkMeshNodes mesh nodes each, and the chunks in parallel, one thread each, instead of
// threading every product:
//   - products on a chunk's matrices stay in cache (a 64-scene graph in one piece ran ~1.5x
//     slower per scene than the same scenes two at a time, on one thread);
//   - training keeps only the activations of the chunks under way, not the whole batch's;
//   - two threads scale by ~1.8x where threading each product gave ~1.3x.
// The network is local to each scene, so chunk outputs are the whole graph's. Parameter
// gradients are summed in up to kLanes fixed lanes (chunk c in lane c mod lanes), then the lanes
// in order: the sum does not depend on the thread count. One scene, or a small graph, runs whole.
class CpuBackend final : public NetworkBackend {
 public:
  static constexpr int kChunkMeshNodes = 1000;
  static constexpr int kLanes = 4;

  explicit CpuBackend(const Network& network) : network_(network) {}
  std::string name() const override { return "cpu"; }

  ConstMatrixView forward(const float* params, const Normalizers& normalizers, const Graph& graph,
                          bool keep_for_backward) override {
    plan_chunks(graph);
    if (chunk_count() <= 1) {
      return network_.forward(params, normalizers, graph, workspace(0), keep_for_backward);
    }
    // Inference needs a workspace per thread; a later backward() needs every chunk's.
    MatrixView output = output_.view(graph.num_mesh_nodes(), 3);
    run_parallel(chunk_count(), [&](int c, int thread) {
      const Graph& chunk = chunk_graphs_[c];
      NetworkWorkspace& ws = workspace(keep_for_backward ? c : thread);
      output.middleRows(chunk_first_node_[c], chunk.num_mesh_nodes()) =
          network_.forward(params, normalizers, chunk, ws, keep_for_backward);
    });
    return output_.cget();
  }

  void backward(const float* params, float* grads, const Graph& graph,
                const ConstMatrixRef& d_output) override {
    if (chunk_count() <= 1) {
      network_.backward(params, grads, graph, d_output, workspace(0));
      return;
    }
    sum_over_lanes(grads, [&](int c, int, float* lane_grads) {
      const Graph& chunk = chunk_graphs_[c];
      network_.backward(params, lane_grads, chunk,
                        d_output.middleRows(chunk_first_node_[c], chunk.num_mesh_nodes()),
                        workspace(c));
    });
  }

  double forward_backward(const float* params, const Normalizers& normalizers, const Graph& graph,
                          float* grads, const LossGradient& loss) override {
    plan_chunks(graph);
    if (chunk_count() <= 1) {
      return NetworkBackend::forward_backward(params, normalizers, graph, grads, loss);
    }
    chunk_loss_.assign(chunk_count(), 0.0);
    // A lane's chunks run one after another in the lane's workspace.
    sum_over_lanes(grads, [&](int c, int lane, float* lane_grads) {
      const Graph& chunk = chunk_graphs_[c];
      NetworkWorkspace& ws = workspace(lane);
      const ConstMatrixView output =
          network_.forward(params, normalizers, chunk, ws, /*keep_for_backward=*/true);
      MatrixView d_output = lane_d_output_[lane].view(output.rows(), 3);
      chunk_loss_[c] = loss(chunk_first_node_[c], output, d_output);
      network_.backward(params, lane_grads, chunk, d_output, ws);
    });
    double total = 0.0;
    for (double part : chunk_loss_) total += part;
    return total;
  }

 private:
  int chunk_count() const { return static_cast<int>(chunk_first_node_.size()); }

  // Consecutive scenes up to kChunkMeshNodes mesh nodes per chunk (at least one scene each);
  // none (the graph runs whole) for one scene or a small graph.
  void plan_chunks(const Graph& graph) {
    const int scenes = graph.num_scenes();
    auto first_node = [&](int scene) {
      return graph.object_first_node[graph.scene_first_object[scene]];
    };
    chunk_first_node_.clear();
    if (scenes <= 1 || graph.num_mesh_nodes() <= kChunkMeshNodes) return;
    bounds_.assign(1, 0);
    while (bounds_.back() < scenes) {
      const int begin = bounds_.back();
      int end = begin + 1;
      while (end < scenes && first_node(end + 1) - first_node(begin) <= kChunkMeshNodes) ++end;
      chunk_first_node_.push_back(first_node(begin));
      bounds_.push_back(end);
    }
    split_scenes(graph, bounds_, chunk_graphs_);
  }

  // grads += Σ over chunks of f(chunk, lane, lane_grads), summed per lane, then lane by lane.
  template <class F>
  void sum_over_lanes(float* grads, F&& f) {
    const int chunks = chunk_count(), lanes = std::min(kLanes, chunks);
    const size_t count = network_.layout().size();
    lane_grads_.resize(lanes);
    lane_d_output_.resize(lanes);
    run_parallel(lanes, [&](int lane) {
      std::vector<float>& sum = lane_grads_[lane];
      sum.assign(count, 0.0f);
      for (int c = lane; c < chunks; c += lanes) f(c, lane, sum.data());
    });
    for (int lane = 0; lane < lanes; ++lane) {
      const float* sum = lane_grads_[lane].data();
      for (size_t i = 0; i < count; ++i) grads[i] += sum[i];
    }
  }

  NetworkWorkspace& workspace(int index) {
    if (static_cast<int>(workspaces_.size()) <= index) workspaces_.resize(index + 1);
    return workspaces_[index];
  }

  // f(0..n-1) on up to Eigen::nbThreads() threads; the products inside run single-threaded.
  template <class F>
  void run_parallel(int n, F&& f) {
    const int threads = std::max(1, std::min(Eigen::nbThreads(), n));
    workspace(std::max(n, threads) - 1);  // before the threads: resizing moves workspaces
    detail::parallel_for(n, threads, detail::Schedule::kOneAtATime, f);
  }

  const Network& network_;
  // This graph's chunks: scene bounds, graphs and where their nodes start in the whole graph.
  std::vector<int> bounds_;
  std::vector<Graph> chunk_graphs_;
  std::vector<int> chunk_first_node_;
  std::vector<NetworkWorkspace> workspaces_;
  std::vector<std::vector<float>> lane_grads_;
  std::vector<Buffer> lane_d_output_;
  std::vector<double> chunk_loss_;
  Buffer output_;
};

}  // namespace

std::unique_ptr<NetworkBackend> make_cpu_backend(const Network& network) {
  return std::make_unique<CpuBackend>(network);
}

}  // namespace fignet
