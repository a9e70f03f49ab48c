// FIGNet's encode–process–decode network (seed C.1): six encoders, M message-passing steps with
// unshared weights and residual connections, and a mesh-node decoder to normalised
// finite-difference accelerations. One code path serves inference (forward) and training
// (forward, then backward into a flat gradient array).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "fignet/graph/graph.h"
#include "fignet/model/config.h"
#include "fignet/model/normalizer.h"
#include "fignet/nn/mlp.h"

namespace fignet {

// The regular (one sender, one receiver) edge types present under a config.
enum class EdgeKind { kMesh, kObjectToMesh, kMeshToObject, kWorld };
enum class NodeSet { kMesh = 0, kObject = 1 };

// Stable name of an edge kind, used in parameter and normaliser names of model files:
// "mesh_edge", "object_to_mesh", "mesh_to_object", "world_edge".
const char* edge_kind_name(EdgeKind kind);

// Input statistics of every node and edge type, and of the target acceleration.
struct Normalizers {
  Normalizer mesh_node, object_node, face_edge, target;
  std::vector<Normalizer> edges;  // one per Network::edge_kinds() entry
};

// Per-call buffers: inputs, latents of every level, MLP caches, gradients. Reused across calls,
// so a steady-state step allocates nothing; one workspace per thread.
class NetworkWorkspace {
 public:
  NetworkWorkspace();
  ~NetworkWorkspace();
  NetworkWorkspace(NetworkWorkspace&&) noexcept;
  NetworkWorkspace& operator=(NetworkWorkspace&&) noexcept;

 private:
  friend class Network;
  struct State;
  std::unique_ptr<State> state_;
};

class Network {
 public:
  explicit Network(const ModelConfig& config);
  ~Network();
  Network(const Network&);
  Network(Network&&) noexcept;
  Network& operator=(const Network&);
  Network& operator=(Network&&) noexcept;

  const ModelConfig& config() const { return config_; }
  const ParameterLayout& layout() const { return layout_; }
  const std::vector<EdgeKind>& edge_kinds() const { return edge_kinds_; }
  Normalizers make_normalizers() const;
  // Adds the graph's input features, block by block, to the statistics (the target is the
  // caller's: only it knows which nodes count).
  void accumulate_input_statistics(const Graph& graph, Normalizers& normalizers) const;

  // Normalised accelerations of every mesh node (rows x 3) for `graph`. With keep_for_backward,
  // every level's activations stay in the workspace for backward().
  ConstMatrixView forward(const float* params, const Normalizers& normalizers, const Graph& graph,
                          NetworkWorkspace& ws, bool keep_for_backward) const;
  // Floating-point operations of one forward() on `graph` (matrix products, as implemented: node
  // blocks of edge updates are multiplied once per node). A backward costs about twice as much.
  double forward_flops(const Graph& graph) const;

  // Accumulates d(loss)/d(params) into `grads`, given d(loss)/d(output) of the last forward.
  void backward(const float* params, float* grads, const Graph& graph,
                const ConstMatrixRef& d_output, NetworkWorkspace& ws) const;

  // Weights of one message-passing step.
  struct Step {
    std::vector<Mlp> edges;  // per regular kind; input [edge, sender, receiver]
    Mlp face;                // input [q_j, v_sj, v_rj] for j = 1..3; output 3L
    Mlp object_node;         // input [v, Σ mesh->object]
    Mlp mesh_node;           // input [v, Σ per incoming regular kind, Σ face-face]
  };

  // The modules and wiring, for backends that run this same computation elsewhere (CUDA).
  const FeatureSizes& sizes() const { return sizes_; }
  bool face_edges() const { return face_edges_; }
  const Mlp& mesh_node_encoder() const { return encode_mesh_node_; }
  const Mlp& object_node_encoder() const { return encode_object_node_; }
  const Mlp& face_encoder() const { return encode_face_; }
  const Mlp& edge_encoder(int kind) const { return encode_edges_[kind]; }
  const Step& step(int k) const { return steps_[k]; }
  const Mlp& decoder() const { return decoder_; }
  const EdgeSet& edges_of(const Graph& graph, int kind) const;
  NodeSet sender_set(int kind) const;
  NodeSet receiver_set(int kind) const;

 private:
  ModelConfig config_;
  FeatureSizes sizes_;
  std::vector<EdgeKind> edge_kinds_;
  bool face_edges_;
  ParameterLayout layout_;
  Mlp encode_mesh_node_, encode_object_node_, encode_face_;
  std::vector<Mlp> encode_edges_;
  std::vector<Step> steps_;
  Mlp decoder_;
};

}  // namespace fignet
