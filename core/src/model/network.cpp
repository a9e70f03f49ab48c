#include "fignet/model/network.h"

#include <algorithm>

#include "fignet/nn/gemm.h"
#include "fignet/nn/ops.h"

namespace fignet {

namespace {

// Latents of one level (after `level` message-passing steps).
struct Level {
  Buffer mesh, object, face;
  std::vector<Buffer> edges;
};

struct StepCache {
  std::vector<MlpCache> edges;
  MlpCache face, object_node, mesh_node;
  std::vector<Buffer> aggregates;  // per kind: Σ of its updated latents at each receiver
  Buffer face_aggregate;
};

}  // namespace

struct NetworkWorkspace::State {
  Buffer in_mesh, in_object, in_face;
  std::vector<Buffer> in_edges;
  std::vector<Level> levels;
  std::vector<StepCache> steps;
  MlpCache encode_mesh, encode_object, encode_face, decoder;
  std::vector<MlpCache> encode_edges;
  Buffer first, scratch, output, d_aggregate;
  Level grads[2];
  int kept_levels = 0;
};

NetworkWorkspace::NetworkWorkspace() : state_(std::make_unique<State>()) {}
NetworkWorkspace::~NetworkWorkspace() = default;
NetworkWorkspace::NetworkWorkspace(NetworkWorkspace&&) noexcept = default;
NetworkWorkspace& NetworkWorkspace::operator=(NetworkWorkspace&&) noexcept = default;

const char* edge_kind_name(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::kMesh:
      return "mesh_edge";
    case EdgeKind::kObjectToMesh:
      return "object_to_mesh";
    case EdgeKind::kMeshToObject:
      return "mesh_to_object";
    case EdgeKind::kWorld:
      return "world_edge";
  }
  return "unknown";
}

Network::~Network() = default;
Network::Network(const Network&) = default;
Network::Network(Network&&) noexcept = default;
Network& Network::operator=(const Network&) = default;
Network& Network::operator=(Network&&) noexcept = default;

Network::Network(const ModelConfig& config)
    : config_((config.validate(), config)),
      sizes_(feature_sizes(config.graph)),
      face_edges_(config.graph.collisions == CollisionEdges::kFaceFace) {
  if (config_.graph.mesh_edges) edge_kinds_.push_back(EdgeKind::kMesh);
  if (config_.graph.object_nodes) {
    edge_kinds_.push_back(EdgeKind::kObjectToMesh);
    edge_kinds_.push_back(EdgeKind::kMeshToObject);
  }
  if (!face_edges_) edge_kinds_.push_back(EdgeKind::kWorld);

  const int l = config_.latent_size, h = config_.mlp_hidden(), ho = config_.object_mlp_hidden();
  auto name_of = [&](int t) { return std::string(edge_kind_name(edge_kinds_[t])); };
  // Encoders (seed C.1.1).
  encode_mesh_node_ = Mlp(layout_, "encoder/mesh_node", {sizes_.mesh_node}, h, l, true);
  if (config_.graph.object_nodes) {
    encode_object_node_ = Mlp(layout_, "encoder/object_node", {sizes_.object_node}, ho, l, true);
  }
  for (size_t t = 0; t < edge_kinds_.size(); ++t) {
    const int width = edge_kinds_[t] == EdgeKind::kWorld ? sizes_.world_edge : sizes_.mesh_edge;
    encode_edges_.push_back(Mlp(layout_, "encoder/" + name_of(t), {width}, h, l, true));
  }
  if (face_edges_) {
    encode_face_ = Mlp(layout_, "encoder/face_edge", {sizes_.face_edge}, h, 3 * l, true);
  }
  // Processor (seed C.1.2).
  for (int k = 0; k < config_.message_passing_steps; ++k) {
    const std::string prefix = "processor/" + std::to_string(k) + "/";
    Step step;
    std::vector<int> mesh_blocks = {l};
    for (size_t t = 0; t < edge_kinds_.size(); ++t) {
      step.edges.push_back(Mlp(layout_, prefix + name_of(t), {l, l, l}, h, l, true));
      if (receiver_set(t) == NodeSet::kMesh) mesh_blocks.push_back(l);
    }
    if (face_edges_) {
      step.face = Mlp(layout_, prefix + "face_edge", std::vector<int>(9, l), h, 3 * l, true);
      mesh_blocks.push_back(l);
    }
    if (config_.graph.object_nodes) {
      step.object_node = Mlp(layout_, prefix + "object_node", {l, l}, ho, l, true);
    }
    step.mesh_node = Mlp(layout_, prefix + "mesh_node", mesh_blocks, h, l, true);
    steps_.push_back(std::move(step));
  }
  // Decoder (seed C.1.3): no LayerNorm.
  decoder_ = Mlp(layout_, "decoder/mesh_node", {l}, h, 3, false);
}

Normalizers Network::make_normalizers() const {
  const auto max = config_.normalizer_max_accumulations;
  Normalizers n{Normalizer(sizes_.mesh_node, max),
                Normalizer(sizes_.object_node, max),
                Normalizer(sizes_.face_edge, max),
                Normalizer(3, max),
                {}};
  for (EdgeKind kind : edge_kinds_) {
    n.edges.emplace_back(kind == EdgeKind::kWorld ? sizes_.world_edge : sizes_.mesh_edge, max);
  }
  return n;
}

void Network::accumulate_input_statistics(const Graph& graph, Normalizers& normalizers) const {
  normalizers.mesh_node.accumulate(graph.mesh_nodes.matrix());
  normalizers.object_node.accumulate(graph.object_nodes.matrix());
  normalizers.face_edge.accumulate(graph.face_edges.features.matrix());
  for (int t = 0; t < static_cast<int>(edge_kinds_.size()); ++t) {
    normalizers.edges[t].accumulate(edges_of(graph, t).features.matrix());
  }
}

const EdgeSet& Network::edges_of(const Graph& graph, int kind) const {
  switch (edge_kinds_[kind]) {
    case EdgeKind::kMesh:
      return graph.mesh_edges;
    case EdgeKind::kObjectToMesh:
      return graph.object_to_mesh;
    case EdgeKind::kMeshToObject:
      return graph.mesh_to_object;
    case EdgeKind::kWorld:
      return graph.world_edges;
  }
  return graph.mesh_edges;
}

NodeSet Network::sender_set(int kind) const {
  return edge_kinds_[kind] == EdgeKind::kObjectToMesh ? NodeSet::kObject : NodeSet::kMesh;
}

NodeSet Network::receiver_set(int kind) const {
  return edge_kinds_[kind] == EdgeKind::kMeshToObject ? NodeSet::kObject : NodeSet::kMesh;
}

namespace {

Buffer& node_latents(Level& level, NodeSet set) {
  return set == NodeSet::kMesh ? level.mesh : level.object;
}

IndexSpan span_of(const std::vector<std::int32_t>& index, int stride = 1, int offset = 0) {
  return {index.data(), static_cast<Eigen::Index>(index.size() / stride), stride, offset};
}

}  // namespace

ConstMatrixView Network::forward(const float* params, const Normalizers& normalizers,
                                 const Graph& graph, NetworkWorkspace& workspace,
                                 bool keep_for_backward) const {
  NetworkWorkspace::State& ws = *workspace.state_;
  const int l = config_.latent_size, m = config_.message_passing_steps;
  const int kinds = static_cast<int>(edge_kinds_.size());
  const Eigen::Index nodes = graph.num_mesh_nodes(), objects = graph.object_nodes.rows();
  const Eigen::Index faces = graph.face_edges.size();
  // Inference keeps two levels and one step's caches; training keeps them all.
  const int levels = keep_for_backward ? m + 1 : 2;
  ws.kept_levels = levels;
  if (static_cast<int>(ws.levels.size()) < levels) ws.levels.resize(levels);
  for (Level& level : ws.levels) level.edges.resize(kinds);
  const int caches = keep_for_backward ? std::max(m, 1) : 1;
  if (static_cast<int>(ws.steps.size()) < caches) ws.steps.resize(caches);
  for (StepCache& c : ws.steps) c.edges.resize(kinds), c.aggregates.resize(kinds);
  ws.in_edges.resize(kinds);
  ws.encode_edges.resize(kinds);

  // 1. Normalise the inputs and encode them (seed C.1.1).
  Level& first_level = ws.levels[0];
  MatrixView in_mesh = ws.in_mesh.view(nodes, sizes_.mesh_node);
  normalizers.mesh_node.normalize(graph.mesh_nodes.matrix(), in_mesh);
  encode_mesh_node_.forward_dense(params, in_mesh, ws.first, ws.encode_mesh,
                                  first_level.mesh.view(nodes, l));
  if (config_.graph.object_nodes) {
    MatrixView in_object = ws.in_object.view(objects, sizes_.object_node);
    normalizers.object_node.normalize(graph.object_nodes.matrix(), in_object);
    encode_object_node_.forward_dense(params, in_object, ws.first, ws.encode_object,
                                      first_level.object.view(objects, l));
  }
  for (int t = 0; t < kinds; ++t) {
    const EdgeSet& edges = edges_of(graph, t);
    MatrixView in = ws.in_edges[t].view(edges.size(), edges.features.cols());
    normalizers.edges[t].normalize(edges.features.matrix(), in);
    encode_edges_[t].forward_dense(params, in, ws.first, ws.encode_edges[t],
                                   first_level.edges[t].view(edges.size(), l));
  }
  if (face_edges_) {
    MatrixView in_face = ws.in_face.view(faces, sizes_.face_edge);
    normalizers.face_edge.normalize(graph.face_edges.features.matrix(), in_face);
    encode_face_.forward_dense(params, in_face, ws.first, ws.encode_face,
                               first_level.face.view(faces, 3 * l));
  }

  // 2. Message passing (seed C.1.2): edges from the old nodes, then nodes from the new edges.
  for (int k = 0; k < m; ++k) {
    const Step& step = steps_[k];
    Level& cur = ws.levels[k % levels];
    Level& next = ws.levels[(k + 1) % levels];
    StepCache& c = ws.steps[keep_for_backward ? k : 0];
    for (int t = 0; t < kinds; ++t) {
      const EdgeSet& edges = edges_of(graph, t);
      const Mlp& mlp = step.edges[t];
      MatrixView z = ws.first.view(edges.size(), mlp.hidden());
      gemm(cur.edges[t].get(), Transpose::kNo, mlp.first_weight(params, 0), Transpose::kNo, z,
           false);
      add_gathered_product(node_latents(cur, sender_set(t)).get(), mlp.first_weight(params, 1),
                           span_of(edges.senders), z, ws.scratch);
      add_gathered_product(node_latents(cur, receiver_set(t)).get(), mlp.first_weight(params, 2),
                           span_of(edges.receivers), z, ws.scratch);
      MatrixView out = next.edges[t].view(edges.size(), l);
      mlp.forward(params, z, c.edges[t], out);
      out += cur.edges[t].get();
    }
    if (face_edges_) {
      const Mlp& mlp = step.face;
      MatrixView z = ws.first.zeros(faces, mlp.hidden());
      const ConstMatrixView q = cur.face.cget();
      for (int j = 0; j < 3; ++j) {
        add_product(q.middleCols(j * l, l), mlp.first_weight(params, 3 * j), z);
        add_gathered_product(cur.mesh.get(), mlp.first_weight(params, 3 * j + 1),
                             span_of(graph.face_edges.senders, 3, j), z, ws.scratch);
        add_gathered_product(cur.mesh.get(), mlp.first_weight(params, 3 * j + 2),
                             span_of(graph.face_edges.receivers, 3, j), z, ws.scratch);
      }
      MatrixView out = next.face.view(faces, 3 * l);
      mlp.forward(params, z, c.face, out);
      out += cur.face.get();
    }
    // Node updates: [v, Σ incoming latents per edge type] with residuals.
    auto update_nodes = [&](NodeSet set, const Mlp& mlp, MlpCache& cache, Eigen::Index count) {
      MatrixView z = ws.first.view(count, mlp.hidden());
      gemm(node_latents(cur, set).get(), Transpose::kNo, mlp.first_weight(params, 0),
           Transpose::kNo, z, false);
      int block = 1;
      for (int t = 0; t < kinds; ++t) {
        if (receiver_set(t) != set) continue;
        MatrixView sum = c.aggregates[t].zeros(count, l);
        scatter_add(next.edges[t].get(), span_of(edges_of(graph, t).receivers), sum);
        add_product(sum, mlp.first_weight(params, block++), z);
      }
      if (set == NodeSet::kMesh && face_edges_) {
        MatrixView sum = c.face_aggregate.zeros(count, l);
        const ConstMatrixView q = next.face.cget();
        for (int j = 0; j < 3; ++j) {
          scatter_add(q.middleCols(j * l, l), span_of(graph.face_edges.receivers, 3, j), sum);
        }
        add_product(sum, mlp.first_weight(params, block++), z);
      }
      MatrixView out = node_latents(next, set).view(count, l);
      mlp.forward(params, z, cache, out);
      out += node_latents(cur, set).get();
    };
    if (config_.graph.object_nodes)
      update_nodes(NodeSet::kObject, step.object_node, c.object_node, objects);
    update_nodes(NodeSet::kMesh, step.mesh_node, c.mesh_node, nodes);
  }

  // 3. Decode accelerations (seed C.1.3).
  MatrixView output = ws.output.view(nodes, 3);
  decoder_.forward_dense(params, ws.levels[m % levels].mesh.get(), ws.first, ws.decoder, output);
  return {ws.output.get().data(), nodes, 3};
}

double Network::forward_flops(const Graph& graph) const {
  const double l = config_.latent_size, m = config_.message_passing_steps;
  const double h = config_.mlp_hidden(), ho = config_.object_mlp_hidden();
  const double nodes = graph.num_mesh_nodes(), objects = graph.object_nodes.rows();
  const double faces = graph.face_edges.size();
  // An MLP of hidden width `hidden` over n rows whose first product is already formed: two more
  // layers.
  auto tail = [&](double n, double out, double hidden) {
    return 2.0 * n * (hidden * hidden + hidden * out);
  };
  auto dense = [&](double n, double in, double out, double hidden) {
    return 2.0 * n * in * hidden + tail(n, out, hidden);
  };
  double flops = dense(nodes, sizes_.mesh_node, l, h) + dense(nodes, l, 3, h);  // encoder, decoder
  if (config_.graph.object_nodes) flops += dense(objects, sizes_.object_node, l, ho);
  if (face_edges_) flops += dense(faces, sizes_.face_edge, 3 * l, h);
  double per_step = 0.0;
  int mesh_blocks = 1 + (face_edges_ ? 1 : 0);
  for (int t = 0; t < static_cast<int>(edge_kinds_.size()); ++t) {
    const double edges = edges_of(graph, t).size();
    flops += dense(edges, edges_of(graph, t).features.cols(), l, h);
    const double senders = sender_set(t) == NodeSet::kMesh ? nodes : objects;
    const double receivers = receiver_set(t) == NodeSet::kMesh ? nodes : objects;
    // A gathered block costs a product per node or per edge, whichever is fewer (ops.h).
    per_step += 2.0 * (edges + std::min(edges, senders) + std::min(edges, receivers)) * l * h +
                tail(edges, l, h);
    if (receiver_set(t) == NodeSet::kMesh) ++mesh_blocks;
  }
  if (face_edges_) {
    per_step += 2.0 * 3 * (faces + 2 * std::min(faces, nodes)) * l * h + tail(faces, 3 * l, h);
  }
  if (config_.graph.object_nodes) per_step += 2.0 * objects * 2 * l * ho + tail(objects, l, ho);
  per_step += 2.0 * nodes * mesh_blocks * l * h + tail(nodes, l, h);
  return flops + m * per_step;
}

void Network::backward(const float* params, float* grads, const Graph& graph,
                       const ConstMatrixRef& d_output, NetworkWorkspace& workspace) const {
  NetworkWorkspace::State& ws = *workspace.state_;
  const int l = config_.latent_size, m = config_.message_passing_steps;
  const int kinds = static_cast<int>(edge_kinds_.size());
  const Eigen::Index nodes = graph.num_mesh_nodes(), objects = graph.object_nodes.rows();
  const Eigen::Index faces = graph.face_edges.size();
  Level* g_next = &ws.grads[0];  // gradients of the level after the step being undone
  Level* g_cur = &ws.grads[1];
  for (Level* g : {g_next, g_cur}) g->edges.resize(kinds);
  auto zero_level = [&](Level& g) {
    g.mesh.zeros(nodes, l);
    g.object.zeros(objects, l);
    g.face.zeros(faces, 3 * l);
    for (int t = 0; t < kinds; ++t) g.edges[t].zeros(edges_of(graph, t).size(), l);
  };
  zero_level(*g_next);
  MatrixRef d_top = g_next->mesh.get();
  decoder_.backward_dense(params, grads, ws.levels[m].mesh.get(), d_output, ws.decoder, &d_top);

  for (int k = m - 1; k >= 0; --k) {
    const Step& step = steps_[k];
    Level& cur = ws.levels[k];
    StepCache& c = ws.steps[k];
    // Residuals pass node gradients straight through.
    g_cur->mesh.view(nodes, l) = g_next->mesh.get();
    g_cur->object.view(objects, l) = g_next->object.get();
    // Node updates: into the old node latents and the new edge latents.
    auto undo_node_update = [&](NodeSet set, const Mlp& mlp, MlpCache& cache, Eigen::Index count) {
      mlp.backward(params, grads, node_latents(*g_next, set).get(), cache);
      const ConstMatrixView d_first = cache.d_first.cget();
      MatrixRef d_old = node_latents(*g_cur, set).get();
      MatrixView dw0 = mlp.first_weight(grads, 0);
      backprop_product(node_latents(cur, set).get(), mlp.first_weight(params, 0), d_first, dw0,
                       &d_old);
      int block = 1;
      for (int t = 0; t < kinds; ++t) {
        if (receiver_set(t) != set) continue;
        MatrixRef d_sum = ws.d_aggregate.zeros(count, l);
        MatrixView dw = mlp.first_weight(grads, block);
        backprop_product(c.aggregates[t].get(), mlp.first_weight(params, block++), d_first, dw,
                         &d_sum);
        gather_add(d_sum, span_of(edges_of(graph, t).receivers), g_next->edges[t].get());
      }
      if (set == NodeSet::kMesh && face_edges_) {
        MatrixRef d_sum = ws.d_aggregate.zeros(count, l);
        MatrixView dw = mlp.first_weight(grads, block);
        backprop_product(c.face_aggregate.get(), mlp.first_weight(params, block++), d_first, dw,
                         &d_sum);
        MatrixView d_q = g_next->face.get();
        for (int j = 0; j < 3; ++j) {
          gather_add(d_sum, span_of(graph.face_edges.receivers, 3, j), d_q.middleCols(j * l, l));
        }
      }
    };
    undo_node_update(NodeSet::kMesh, step.mesh_node, c.mesh_node, nodes);
    if (config_.graph.object_nodes)
      undo_node_update(NodeSet::kObject, step.object_node, c.object_node, objects);
    // Edge gradients are now complete for this level; residuals pass them through.
    for (int t = 0; t < kinds; ++t) {
      g_cur->edges[t].view(edges_of(graph, t).size(), l) = g_next->edges[t].get();
    }
    g_cur->face.view(faces, 3 * l) = g_next->face.get();
    // Edge updates: into the old edge latents and both endpoints' old node latents.
    for (int t = 0; t < kinds; ++t) {
      const EdgeSet& edges = edges_of(graph, t);
      const Mlp& mlp = step.edges[t];
      mlp.backward(params, grads, g_next->edges[t].get(), c.edges[t]);
      const ConstMatrixView d_first = c.edges[t].d_first.cget();
      MatrixRef d_edges = g_cur->edges[t].get();
      MatrixView dw0 = mlp.first_weight(grads, 0), dw1 = mlp.first_weight(grads, 1),
                 dw2 = mlp.first_weight(grads, 2);
      backprop_product(cur.edges[t].get(), mlp.first_weight(params, 0), d_first, dw0, &d_edges);
      MatrixRef d_senders = node_latents(*g_cur, sender_set(t)).get();
      backprop_gathered_product(node_latents(cur, sender_set(t)).get(), mlp.first_weight(params, 1),
                                span_of(edges.senders), d_first, dw1, &d_senders, ws.scratch);
      MatrixRef d_receivers = node_latents(*g_cur, receiver_set(t)).get();
      backprop_gathered_product(node_latents(cur, receiver_set(t)).get(),
                                mlp.first_weight(params, 2), span_of(edges.receivers), d_first, dw2,
                                &d_receivers, ws.scratch);
    }
    if (face_edges_) {
      const Mlp& mlp = step.face;
      mlp.backward(params, grads, g_next->face.get(), c.face);
      const ConstMatrixView d_first = c.face.d_first.cget();
      const ConstMatrixView q = cur.face.cget();
      MatrixView d_q = g_cur->face.get();
      MatrixRef d_mesh = g_cur->mesh.get();
      for (int j = 0; j < 3; ++j) {
        MatrixView dwq = mlp.first_weight(grads, 3 * j), dws = mlp.first_weight(grads, 3 * j + 1),
                   dwr = mlp.first_weight(grads, 3 * j + 2);
        MatrixRef d_qj = d_q.middleCols(j * l, l);
        backprop_product(q.middleCols(j * l, l), mlp.first_weight(params, 3 * j), d_first, dwq,
                         &d_qj);
        backprop_gathered_product(cur.mesh.get(), mlp.first_weight(params, 3 * j + 1),
                                  span_of(graph.face_edges.senders, 3, j), d_first, dws, &d_mesh,
                                  ws.scratch);
        backprop_gathered_product(cur.mesh.get(), mlp.first_weight(params, 3 * j + 2),
                                  span_of(graph.face_edges.receivers, 3, j), d_first, dwr, &d_mesh,
                                  ws.scratch);
      }
    }
    std::swap(g_next, g_cur);
  }

  // Encoders: parameter gradients only (inputs are data).
  encode_mesh_node_.backward_dense(params, grads, ws.in_mesh.get(), g_next->mesh.get(),
                                   ws.encode_mesh, nullptr);
  if (config_.graph.object_nodes) {
    encode_object_node_.backward_dense(params, grads, ws.in_object.get(), g_next->object.get(),
                                       ws.encode_object, nullptr);
  }
  for (int t = 0; t < kinds; ++t) {
    encode_edges_[t].backward_dense(params, grads, ws.in_edges[t].get(), g_next->edges[t].get(),
                                    ws.encode_edges[t], nullptr);
  }
  if (face_edges_) {
    encode_face_.backward_dense(params, grads, ws.in_face.get(), g_next->face.get(), ws.encode_face,
                                nullptr);
  }
}

}  // namespace fignet
