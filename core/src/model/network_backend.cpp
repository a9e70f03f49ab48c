#include "fignet/model/network_backend.h"

#include <algorithm>
#include <numeric>

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
// kChunkMeshNodes mesh nodes each (more in batches of over kMaxChunks such chunks), and the chunks
// in parallel, one thread each, instead of threading every product:
//   - products on a chunk's matrices stay in cache (a 64-scene graph in one piece ran ~1.5x
//     slower per scene than the same scenes two at a time, on one thread);
//   - training keeps only the activations of the chunks under way, not the whole batch's;
//   - two threads scale by ~1.8x where threading each product gave ~1.3x.
// The network is local to each scene, so chunk outputs are the whole graph's. Each chunk's
// parameter gradients go into a buffer of its own, added up in chunk order: the sum does not
// depend on the thread count nor on which thread ran which chunk, so idle threads take the next
// chunk, largest first (a scene's cost varies several-fold with its contacts, and fixed shares
// left one of two threads idle for a seventh of their time). One scene, or a small graph, runs
// whole.
class CpuBackend final : public NetworkBackend {
 public:
  // About one MOVi-A scene: with fewer rows per chunk its matrices stay in cache, and the
  // threads share a batch of 8 more evenly (500 against 1000: 5 % less network time per step on
  // one thread, 7 % on two; docs/network.md).
  static constexpr int kChunkMeshNodes = 500;
  static constexpr int kMaxChunks = 16;

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
    run_parallel(chunk_count(), [&](int i, int thread) {
      const int c = largest_first_[i];
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
    sum_over_chunks(grads, [&](int c, int, float* chunk_grads) {
      const Graph& chunk = chunk_graphs_[c];
      network_.backward(params, chunk_grads, chunk,
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
    const size_t threads = static_cast<size_t>(team_size(chunk_count()));
    if (thread_d_output_.size() < threads) thread_d_output_.resize(threads);
    // A thread's chunks run one after another in the thread's workspace.
    sum_over_chunks(grads, [&](int c, int thread, float* chunk_grads) {
      const Graph& chunk = chunk_graphs_[c];
      NetworkWorkspace& ws = workspace(thread);
      const ConstMatrixView output =
          network_.forward(params, normalizers, chunk, ws, /*keep_for_backward=*/true);
      MatrixView d_output = thread_d_output_[thread].view(output.rows(), 3);
      chunk_loss_[c] = loss(chunk_first_node_[c], output, d_output);
      network_.backward(params, chunk_grads, chunk, d_output, ws);
    });
    double total = 0.0;
    for (double part : chunk_loss_) total += part;
    return total;
  }

 private:
  // Parameters whose gradients one thread adds up over the chunks at a time.
  static constexpr size_t kSumBlock = 16384;

  int chunk_count() const { return static_cast<int>(chunk_first_node_.size()); }

  // Consecutive scenes up to kChunkMeshNodes mesh nodes per chunk (at least one scene each);
  // none (the graph runs whole) for one scene or a small graph. `largest_first_` orders them by
  // their edges, the network's work.
  void plan_chunks(const Graph& graph) {
    const int scenes = graph.num_scenes();
    auto first_node = [&](int scene) {
      return graph.object_first_node[graph.scene_first_object[scene]];
    };
    chunk_first_node_.clear();
    if (scenes <= 1 || graph.num_mesh_nodes() <= kChunkMeshNodes) return;
    // Larger chunks for a large batch: every chunk holds a gradient buffer of all parameters.
    const int chunk_nodes =
        std::max(kChunkMeshNodes, (graph.num_mesh_nodes() + kMaxChunks - 1) / kMaxChunks);
    bounds_.assign(1, 0);
    while (bounds_.back() < scenes) {
      const int begin = bounds_.back();
      int end = begin + 1;
      while (end < scenes && first_node(end + 1) - first_node(begin) <= chunk_nodes) ++end;
      chunk_first_node_.push_back(first_node(begin));
      bounds_.push_back(end);
    }
    split_scenes(graph, bounds_, chunk_graphs_);
    largest_first_.resize(chunk_first_node_.size());
    std::iota(largest_first_.begin(), largest_first_.end(), 0);
    auto work = [&](int c) {
      const Graph& chunk = chunk_graphs_[c];
      return chunk.mesh_edges.size() + chunk.face_edges.size() + chunk.num_mesh_nodes();
    };
    std::stable_sort(largest_first_.begin(), largest_first_.end(),
                     [&](int a, int b) { return work(a) > work(b); });
  }

  // grads += Σ over chunks of f(chunk, thread, chunk_grads), in chunk order for every parameter.
  template <class F>
  void sum_over_chunks(float* grads, F&& f) {
    const int chunks = chunk_count();
    const size_t count = network_.layout().size();
    if (static_cast<int>(chunk_grads_.size()) < chunks) chunk_grads_.resize(chunks);
    // The buffers are zero here: new ones are made so, and the sum below leaves them so.
    try {
      run_parallel(chunks, [&](int i, int thread) {
        const int c = largest_first_[i];
        std::vector<float>& sum = chunk_grads_[c];
        if (sum.size() != count) sum.assign(count, 0.0f);
        f(c, thread, sum.data());
      });
    } catch (...) {
      // A chunk that threw leaves the others' buffers filled and never summed.
      for (std::vector<float>& sum : chunk_grads_) std::fill(sum.begin(), sum.end(), 0.0f);
      throw;
    }
    // Each block of a buffer is zeroed for the next call just after it is added, while in cache:
    // a separate pass over every buffer cost about as much as the sum itself.
    detail::parallel_for_blocks(count, kSumBlock, Eigen::nbThreads(),
                                [&](size_t begin, size_t end) {
                                  for (int c = 0; c < chunks; ++c) {
                                    float* sum = chunk_grads_[c].data();
                                    for (size_t i = begin; i < end; ++i) grads[i] += sum[i];
                                    std::fill(sum + begin, sum + end, 0.0f);
                                  }
                                });
  }

  NetworkWorkspace& workspace(int index) {
    if (static_cast<int>(workspaces_.size()) <= index) workspaces_.resize(index + 1);
    return workspaces_[index];
  }

  // The threads that run_parallel(n, ...) uses.
  static int team_size(int n) { return std::max(1, std::min(Eigen::nbThreads(), n)); }

  // f(0..n-1) on up to Eigen::nbThreads() threads, the next index to the next idle one; the
  // products inside run single-threaded.
  template <class F>
  void run_parallel(int n, F&& f) {
    const int threads = team_size(n);
    workspace(std::max(n, threads) - 1);  // before the threads: resizing moves workspaces
    detail::parallel_for(n, threads, detail::Schedule::kOneAtATime, f);
  }

  const Network& network_;
  // This graph's chunks: scene bounds, graphs and where their nodes start in the whole graph.
  std::vector<int> bounds_;
  std::vector<Graph> chunk_graphs_;
  std::vector<int> chunk_first_node_;
  std::vector<int> largest_first_;
  std::vector<NetworkWorkspace> workspaces_;
  std::vector<std::vector<float>> chunk_grads_;
  std::vector<Buffer> thread_d_output_;
  std::vector<double> chunk_loss_;
  Buffer output_;
};

}  // namespace

std::unique_ptr<NetworkBackend> make_cpu_backend(const Network& network) {
  return std::make_unique<CpuBackend>(network);
}

}  // namespace fignet
