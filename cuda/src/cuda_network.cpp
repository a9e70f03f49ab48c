// The network's forward and backward passes on a GPU: network.cpp's computation step by step,
// with device buffers in place of host ones. Where this file and network.cpp differ, network.cpp
// is the reference (tests/cuda compare the two).
#include <fmt/format.h>

#include <array>
#include <chrono>
#include <vector>

#include "device_memory.h"
#include "fignet/cuda/cuda_backend.h"
#include "kernels.h"

namespace fignet::cuda {

namespace {

using Index32 = std::int32_t;

// Row-major C = op(A)·op(B) + beta·C through column-major cuBLAS (Cᵀ = op(B)ᵀ·op(A)ᵀ).
void gemm(cublasHandle_t blas, DeviceMatrix a, bool transpose_a, DeviceMatrix b, bool transpose_b,
          DeviceMatrix c, float beta, cudaStream_t stream) {
  const int k = transpose_a ? a.rows : a.cols;
  if (c.rows == 0 || c.cols == 0) return;
  if (k == 0) {
    if (beta == 0.0f) fill(c, 0.0f, stream);
    return;
  }
  const float one = 1.0f;
  check(cublasSgemm(blas, transpose_b ? CUBLAS_OP_T : CUBLAS_OP_N,
                    transpose_a ? CUBLAS_OP_T : CUBLAS_OP_N, c.cols, c.rows, k, &one, b.data, b.ld,
                    a.data, a.ld, &beta, c.data, c.ld),
        "cublasSgemm");
}

DeviceMatrix tensor(const float* params, size_t offset, int rows, int cols) {
  return {const_cast<float*>(params) + offset, rows, cols, cols};
}

DeviceMatrix first_weight(const Mlp& mlp, const float* params, int block) {
  const ConstMatrixView w = mlp.first_weight(params, block);  // a view; nothing is read
  return {const_cast<float*>(w.data()), static_cast<int>(w.rows()), static_cast<int>(w.cols()),
          static_cast<int>(w.cols())};
}

// Rows of an edge list grouped by the node they name (host side of DeviceSegments).
struct Segments {
  DeviceArray<Index32> offsets, rows;
  DeviceSegments view;

  void build(const Index32* index, int count, int stride, int offset, int nodes,
             cudaStream_t stream, std::vector<Index32>& host_offsets,
             std::vector<Index32>& host_rows) {
    host_offsets.assign(static_cast<size_t>(nodes) + 1, 0);
    for (int e = 0; e < count; ++e) ++host_offsets[index[size_t(e) * stride + offset] + 1];
    for (int i = 0; i < nodes; ++i) host_offsets[i + 1] += host_offsets[i];
    host_rows.resize(count);
    std::vector<Index32> cursor(host_offsets.begin(), host_offsets.end() - 1);
    for (int e = 0; e < count; ++e) host_rows[cursor[index[size_t(e) * stride + offset]]++] = e;
    view = {offsets.upload(host_offsets.data(), host_offsets.size(), stream),
            rows.upload(host_rows.data(), host_rows.size(), stream), nodes};
    // Copies from pageable memory return once the staging vectors have been read: they can be
    // refilled by the next build at once.
  }
};

struct DeviceEdges {
  DeviceArray<float> features;
  DeviceArray<Index32> senders, receivers;
  Segments by_sender, by_receiver;
  int count = 0;
};

struct MlpCache {
  DeviceBuffer hidden1, hidden2, normalized, inv_std, d_hidden, d_pre_norm, d_first, product;
};

struct Level {
  DeviceBuffer mesh, object, face;
  std::vector<DeviceBuffer> edges;
};

struct StepCache {
  std::vector<MlpCache> edges;
  MlpCache face, object_node, mesh_node;
  std::vector<DeviceBuffer> aggregates;
  DeviceBuffer face_aggregate;
};

class CudaBackend final : public NetworkBackend {
 public:
  CudaBackend(const Network& network, const CudaOptions& options) : network_(network) {
    const int devices = device_count();
    if (options.device < 0 || options.device >= devices) {
      throw DeviceError(fmt::format("CUDA device {} requested; this process sees {} device{}",
                                    options.device, devices, devices == 1 ? "" : "s"));
    }
    check(cudaSetDevice(options.device), "cudaSetDevice");
    check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate");
    check(cublasCreate(&blas_), "cublasCreate");
    check(cublasSetStream(blas_, stream_), "cublasSetStream");
    check(cublasSetMathMode(blas_, options.tf32 ? CUBLAS_TF32_TENSOR_OP_MATH : CUBLAS_DEFAULT_MATH),
          "cublasSetMathMode");
    name_ = fmt::format("cuda:{} {}, tf32 {}", options.device, describe_device(options.device),
                        options.tf32 ? "on" : "off");
  }
  ~CudaBackend() override {
    cublasDestroy(blas_);
    cudaStreamDestroy(stream_);
  }

  std::string name() const override { return name_; }
  void parameters_changed() override { uploaded_params_ = nullptr; }
  std::string profile() const override {
    const double calls = std::max(1.0, double(forward_calls_));
    return fmt::format(
        "per forward: {:.2f} ms uploading graph and parameters, {:.2f} ms forward; per backward: "
        "{:.2f} ms ({} forward, {} backward calls)",
        1e3 * upload_seconds_ / calls, 1e3 * forward_seconds_ / calls,
        1e3 * backward_seconds_ / std::max(1.0, double(backward_calls_)), forward_calls_,
        backward_calls_);
  }

  ConstMatrixView forward(const float* params, const Normalizers& normalizers, const Graph& graph,
                          bool keep_for_backward) override;
  void backward(const float* params, float* grads, const Graph& graph,
                const ConstMatrixRef& d_output) override;

 private:
  // Inputs.
  void upload_parameters(const float* params);
  void upload_graph(const Graph& graph);
  const float* upload_statistics(const Normalizers& normalizers);
  // The products of ops.h.
  void add_product(DeviceMatrix x, DeviceMatrix w, DeviceMatrix z) {
    if (x.rows > 0) gemm(blas_, x, false, w, false, z, 1.0f, stream_);
  }
  void add_gathered_product(DeviceMatrix x, DeviceMatrix w, DeviceIndex index, DeviceMatrix z) {
    if (index.count == 0) return;
    const DeviceMatrix per_node = scratch_.view(x.rows, w.cols);
    gemm(blas_, x, false, w, false, per_node, 0.0f, stream_);
    gather_add(per_node, index, z, stream_);
  }
  void backprop_product(DeviceMatrix x, DeviceMatrix w, DeviceMatrix dz, DeviceMatrix dw,
                        const DeviceMatrix* dx) {
    if (x.rows == 0) return;
    gemm(blas_, x, true, dz, false, dw, 1.0f, stream_);
    if (dx) gemm(blas_, dz, false, w, true, *dx, 1.0f, stream_);
  }
  void backprop_gathered_product(DeviceMatrix x, DeviceMatrix w, const DeviceSegments& segments,
                                 int count, DeviceMatrix dz, DeviceMatrix dw,
                                 const DeviceMatrix* dx) {
    if (count == 0) return;
    const DeviceMatrix per_node = scratch_.view(x.rows, w.cols);
    segment_sum(dz, segments, per_node, /*accumulate=*/false, stream_);
    gemm(blas_, x, true, per_node, false, dw, 1.0f, stream_);
    if (dx) gemm(blas_, per_node, false, w, true, *dx, 1.0f, stream_);
  }
  // y += Σ over rows of m.
  void add_column_sums(DeviceMatrix m, float* y) {
    if (m.rows == 0) return;
    if (ones_rows_ < m.rows) {
      const std::vector<float> ones(m.rows, 1.0f);
      ones_.upload(ones.data(), ones.size(), stream_);
      ones_rows_ = m.rows;
    }
    const float one = 1.0f;
    check(cublasSgemv(blas_, CUBLAS_OP_N, m.cols, m.rows, &one, m.data, m.ld, ones_.data(), 1, &one,
                      y, 1),
          "cublasSgemv");
  }
  // The MLP of mlp.h.
  void mlp_forward(const Mlp& mlp, const float* p, DeviceMatrix first, MlpCache& cache,
                   DeviceMatrix out);
  void mlp_backward(const Mlp& mlp, const float* p, float* g, DeviceMatrix d_out, MlpCache& cache);
  void mlp_forward_dense(const Mlp& mlp, const float* p, DeviceMatrix x, MlpCache& cache,
                         DeviceMatrix out) {
    const MlpTensors t = mlp.tensors();
    const DeviceMatrix z = first_.view(x.rows, mlp.hidden());
    gemm(blas_, x, false, tensor(p, t.w0, mlp.input(), mlp.hidden()), false, z, 0.0f, stream_);
    mlp_forward(mlp, p, z, cache, out);
  }
  void mlp_backward_dense(const Mlp& mlp, const float* p, float* g, DeviceMatrix x,
                          DeviceMatrix d_out, MlpCache& cache, const DeviceMatrix* dx) {
    mlp_backward(mlp, p, g, d_out, cache);
    const MlpTensors t = mlp.tensors();
    backprop_product(x, tensor(p, t.w0, mlp.input(), mlp.hidden()), cache.d_first.get(),
                     tensor(g, t.w0, mlp.input(), mlp.hidden()), dx);
  }
  DeviceBuffer& node_latents(Level& level, NodeSet set) {
    return set == NodeSet::kMesh ? level.mesh : level.object;
  }
  void copy(DeviceMatrix from, DeviceMatrix to) {
    if (from.rows == 0 || from.cols == 0) return;
    check(
        cudaMemcpy2DAsync(to.data, to.ld * sizeof(float), from.data, from.ld * sizeof(float),
                          from.cols * sizeof(float), from.rows, cudaMemcpyDeviceToDevice, stream_),
        "cudaMemcpy2DAsync");
  }
  void add_into(DeviceMatrix from, DeviceMatrix to) {  // both contiguous, same shape
    add(from.data, to.data, std::int64_t(from.rows) * from.cols, stream_);
  }
  // Face latents (faces x 3L) seen as one row per (face, j): 3·faces x L.
  static DeviceMatrix as_face_slots(DeviceMatrix face, int l) {
    return {face.data, face.rows * 3, l, l};
  }

  const Network& network_;
  std::string name_;
  cudaStream_t stream_ = nullptr;
  cublasHandle_t blas_ = nullptr;

  // Parameters and gradients.
  DeviceArray<float> params_, grads_;
  const float* uploaded_params_ = nullptr;
  std::vector<float> host_grads_;
  // The graph of the last forward.
  int nodes_ = 0, objects_ = 0, faces_ = 0;
  DeviceArray<float> mesh_features_, object_features_, face_features_, statistics_;
  std::vector<DeviceEdges> edges_;
  DeviceArray<Index32> face_senders_, face_receivers_;
  Segments face_slots_by_receiver_;
  std::array<Segments, 3> face_by_sender_, face_by_receiver_;
  std::vector<Index32> staging_offsets_, staging_rows_;
  std::vector<float> staging_statistics_;
  // Workspace.
  DeviceBuffer in_mesh_, in_object_, in_face_;
  std::vector<DeviceBuffer> in_edges_;
  std::vector<Level> levels_;
  std::vector<StepCache> steps_;
  MlpCache encode_mesh_, encode_object_, encode_face_, decoder_;
  std::vector<MlpCache> encode_edges_;
  DeviceBuffer first_, scratch_, output_, d_aggregate_, d_output_;
  Level grads_levels_[2];
  DeviceArray<float> ones_;
  int ones_rows_ = 0;
  std::vector<float> host_output_;
  // profile()'s wall-clock sums.
  double upload_seconds_ = 0.0, forward_seconds_ = 0.0, backward_seconds_ = 0.0;
  std::int64_t forward_calls_ = 0, backward_calls_ = 0;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CudaBackend::upload_parameters(const float* params) {
  if (params == uploaded_params_) return;
  const size_t count = network_.layout().size();
  params_.upload(params, count, stream_);
  uploaded_params_ = params;
}

void CudaBackend::upload_graph(const Graph& graph) {
  nodes_ = graph.num_mesh_nodes();
  objects_ = graph.object_nodes.rows();
  faces_ = graph.face_edges.size();
  mesh_features_.upload(graph.mesh_nodes.row(0),
                        size_t(graph.mesh_nodes.rows()) * graph.mesh_nodes.cols(), stream_);
  object_features_.upload(graph.object_nodes.row(0),
                          size_t(graph.object_nodes.rows()) * graph.object_nodes.cols(), stream_);
  face_features_.upload(graph.face_edges.features.row(0),
                        size_t(faces_) * graph.face_edges.features.cols(), stream_);
  const int kinds = static_cast<int>(network_.edge_kinds().size());
  edges_.resize(kinds);
  auto set_size = [&](NodeSet set) { return set == NodeSet::kMesh ? nodes_ : objects_; };
  for (int t = 0; t < kinds; ++t) {
    const EdgeSet& edges = network_.edges_of(graph, t);
    DeviceEdges& d = edges_[t];
    d.count = edges.size();
    d.features.upload(edges.features.row(0), size_t(d.count) * edges.features.cols(), stream_);
    d.senders.upload(edges.senders.data(), edges.senders.size(), stream_);
    d.receivers.upload(edges.receivers.data(), edges.receivers.size(), stream_);
    d.by_sender.build(edges.senders.data(), d.count, 1, 0, set_size(network_.sender_set(t)),
                      stream_, staging_offsets_, staging_rows_);
    d.by_receiver.build(edges.receivers.data(), d.count, 1, 0, set_size(network_.receiver_set(t)),
                        stream_, staging_offsets_, staging_rows_);
  }
  if (network_.face_edges()) {
    const FaceEdgeSet& f = graph.face_edges;
    face_senders_.upload(f.senders.data(), f.senders.size(), stream_);
    face_receivers_.upload(f.receivers.data(), f.receivers.size(), stream_);
    face_slots_by_receiver_.build(f.receivers.data(), 3 * faces_, 1, 0, nodes_, stream_,
                                  staging_offsets_, staging_rows_);
    for (int j = 0; j < 3; ++j) {
      face_by_sender_[j].build(f.senders.data(), faces_, 3, j, nodes_, stream_, staging_offsets_,
                               staging_rows_);
      face_by_receiver_[j].build(f.receivers.data(), faces_, 3, j, nodes_, stream_,
                                 staging_offsets_, staging_rows_);
    }
  }
}

// Means and inverse standard deviations of every input normaliser, in one device array:
// [mesh, object, face, edges...], each as mean then 1/std.
const float* CudaBackend::upload_statistics(const Normalizers& normalizers) {
  staging_statistics_.clear();
  auto append = [&](const Normalizer& n) {
    for (int c = 0; c < n.size(); ++c) staging_statistics_.push_back(n.mean()[c]);
    for (int c = 0; c < n.size(); ++c) staging_statistics_.push_back(1.0f / n.std()[c]);
  };
  append(normalizers.mesh_node);
  append(normalizers.object_node);
  append(normalizers.face_edge);
  for (const Normalizer& n : normalizers.edges) append(n);
  return statistics_.upload(staging_statistics_.data(), staging_statistics_.size(), stream_);
}

void CudaBackend::mlp_forward(const Mlp& mlp, const float* p, DeviceMatrix first, MlpCache& cache,
                              DeviceMatrix out) {
  const MlpTensors t = mlp.tensors();
  const int n = first.rows, h = mlp.hidden(), o = mlp.output();
  // Hidden layers: ReLU(x·W + b).
  const DeviceMatrix h1 = cache.hidden1.view(n, h);
  bias_relu(first, p + t.b0, h1, stream_);
  const DeviceMatrix h2 = cache.hidden2.view(n, h);
  gemm(blas_, h1, false, tensor(p, t.w1, h, h), false, h2, 0.0f, stream_);
  bias_relu(h2, p + t.b1, h2, stream_);
  gemm(blas_, h2, false, tensor(p, t.w2, h, o), false, out, 0.0f, stream_);
  add_bias(out, p + t.b2, stream_);
  if (!mlp.layer_norm()) return;
  layer_norm_forward(out, p + t.scale, p + t.offset, Mlp::kLayerNormEpsilon,
                     cache.normalized.view(n, o).data, cache.inv_std.view(n, 1).data, stream_);
}

void CudaBackend::mlp_backward(const Mlp& mlp, const float* p, float* g, DeviceMatrix d_out,
                               MlpCache& cache) {
  const MlpTensors t = mlp.tensors();
  const int n = d_out.rows, h = mlp.hidden(), o = mlp.output();
  // Through LayerNorm, with its scale's and offset's gradients.
  DeviceMatrix d_pre = d_out;
  if (mlp.layer_norm()) {
    d_pre = cache.d_pre_norm.view(n, o);
    const DeviceMatrix product = cache.product.view(n, o);
    layer_norm_backward(d_out, cache.normalized.get().data, cache.inv_std.get().data, p + t.scale,
                        d_pre.data, product.data, stream_);
    add_column_sums(product, g + t.scale);
    add_column_sums(d_out, g + t.offset);
  }
  // Output layer.
  const DeviceMatrix h1 = cache.hidden1.get(), h2 = cache.hidden2.get();
  gemm(blas_, h2, true, d_pre, false, tensor(g, t.w2, h, o), 1.0f, stream_);
  add_column_sums(d_pre, g + t.b2);
  const DeviceMatrix d_h2 = cache.d_hidden.view(n, h);
  gemm(blas_, d_pre, false, tensor(p, t.w2, h, o), true, d_h2, 0.0f, stream_);
  relu_mask(d_h2, h2.data, stream_);
  // Second hidden layer.
  gemm(blas_, h1, true, d_h2, false, tensor(g, t.w1, h, h), 1.0f, stream_);
  add_column_sums(d_h2, g + t.b1);
  const DeviceMatrix d_first = cache.d_first.view(n, h);
  gemm(blas_, d_h2, false, tensor(p, t.w1, h, h), true, d_first, 0.0f, stream_);
  relu_mask(d_first, h1.data, stream_);
  add_column_sums(d_first, g + t.b0);
}

ConstMatrixView CudaBackend::forward(const float* params, const Normalizers& normalizers,
                                     const Graph& graph, bool keep_for_backward) {
  const ModelConfig& config = network_.config();
  const FeatureSizes& sizes = network_.sizes();
  const int l = config.latent_size, m = config.message_passing_steps;
  const int kinds = static_cast<int>(network_.edge_kinds().size());
  const bool face_edges = network_.face_edges(), object_nodes = config.graph.object_nodes;
  auto start = std::chrono::steady_clock::now();
  upload_parameters(params);
  upload_graph(graph);
  const float* statistics = upload_statistics(normalizers);
  const float* p = params_.data();
  check(cudaStreamSynchronize(stream_), "upload");
  upload_seconds_ += seconds_since(start);
  start = std::chrono::steady_clock::now();
  ++forward_calls_;
  const int levels = keep_for_backward ? m + 1 : 2;
  if (static_cast<int>(levels_.size()) < levels) levels_.resize(levels);
  for (Level& level : levels_) level.edges.resize(kinds);
  const int caches = keep_for_backward ? std::max(m, 1) : 1;
  if (static_cast<int>(steps_.size()) < caches) steps_.resize(caches);
  for (StepCache& c : steps_) c.edges.resize(kinds), c.aggregates.resize(kinds);
  in_edges_.resize(kinds);
  encode_edges_.resize(kinds);

  // 1. Normalise the inputs and encode them.
  auto normalized_input = [&](DeviceBuffer& buffer, const float* features, int rows, int cols) {
    const DeviceMatrix in = buffer.view(rows, cols);
    normalize(features, statistics, statistics + cols, rows, cols, in.data, stream_);
    statistics += 2 * cols;
    return in;
  };
  Level& first_level = levels_[0];
  const DeviceMatrix in_mesh =
      normalized_input(in_mesh_, mesh_features_.data(), nodes_, sizes.mesh_node);
  mlp_forward_dense(network_.mesh_node_encoder(), p, in_mesh, encode_mesh_,
                    first_level.mesh.view(nodes_, l));
  const DeviceMatrix in_object =
      normalized_input(in_object_, object_features_.data(), objects_, sizes.object_node);
  if (object_nodes) {
    mlp_forward_dense(network_.object_node_encoder(), p, in_object, encode_object_,
                      first_level.object.view(objects_, l));
  }
  const DeviceMatrix in_face =
      normalized_input(in_face_, face_features_.data(), faces_, sizes.face_edge);
  for (int t = 0; t < kinds; ++t) {
    const int cols = network_.edges_of(graph, t).features.cols();
    const DeviceMatrix in =
        normalized_input(in_edges_[t], edges_[t].features.data(), edges_[t].count, cols);
    mlp_forward_dense(network_.edge_encoder(t), p, in, encode_edges_[t],
                      first_level.edges[t].view(edges_[t].count, l));
  }
  if (face_edges) {
    mlp_forward_dense(network_.face_encoder(), p, in_face, encode_face_,
                      first_level.face.view(faces_, 3 * l));
  }

  // 2. Message passing: edges from the old nodes, then nodes from the new edges.
  for (int k = 0; k < m; ++k) {
    const Network::Step& step = network_.step(k);
    Level& cur = levels_[k % levels];
    Level& next = levels_[(k + 1) % levels];
    StepCache& c = steps_[keep_for_backward ? k : 0];
    for (int t = 0; t < kinds; ++t) {
      const DeviceEdges& edges = edges_[t];
      const Mlp& mlp = step.edges[t];
      const DeviceMatrix z = first_.view(edges.count, mlp.hidden());
      gemm(blas_, cur.edges[t].get(), false, first_weight(mlp, p, 0), false, z, 0.0f, stream_);
      add_gathered_product(node_latents(cur, network_.sender_set(t)).get(), first_weight(mlp, p, 1),
                           {edges.senders.data(), edges.count, 1, 0}, z);
      add_gathered_product(node_latents(cur, network_.receiver_set(t)).get(),
                           first_weight(mlp, p, 2), {edges.receivers.data(), edges.count, 1, 0}, z);
      const DeviceMatrix out = next.edges[t].view(edges.count, l);
      mlp_forward(mlp, p, z, c.edges[t], out);
      add_into(cur.edges[t].get(), out);
    }
    if (face_edges) {
      const Mlp& mlp = step.face;
      const DeviceMatrix z = first_.zeros(faces_, mlp.hidden(), stream_);
      const DeviceMatrix q = cur.face.get();
      for (int j = 0; j < 3; ++j) {
        add_product(q.columns(j * l, l), first_weight(mlp, p, 3 * j), z);
        add_gathered_product(cur.mesh.get(), first_weight(mlp, p, 3 * j + 1),
                             {face_senders_.data(), faces_, 3, j}, z);
        add_gathered_product(cur.mesh.get(), first_weight(mlp, p, 3 * j + 2),
                             {face_receivers_.data(), faces_, 3, j}, z);
      }
      const DeviceMatrix out = next.face.view(faces_, 3 * l);
      mlp_forward(mlp, p, z, c.face, out);
      add_into(cur.face.get(), out);
    }
    // Node updates: [v, Σ incoming latents per edge type] with residuals.
    auto update_nodes = [&](NodeSet set, const Mlp& mlp, MlpCache& cache, int count) {
      const DeviceMatrix z = first_.view(count, mlp.hidden());
      gemm(blas_, node_latents(cur, set).get(), false, first_weight(mlp, p, 0), false, z, 0.0f,
           stream_);
      int block = 1;
      for (int t = 0; t < kinds; ++t) {
        if (network_.receiver_set(t) != set) continue;
        const DeviceMatrix sum = c.aggregates[t].view(count, l);
        segment_sum(next.edges[t].get(), edges_[t].by_receiver.view, sum, false, stream_);
        add_product(sum, first_weight(mlp, p, block++), z);
      }
      if (set == NodeSet::kMesh && face_edges) {
        const DeviceMatrix sum = c.face_aggregate.view(count, l);
        segment_sum(as_face_slots(next.face.get(), l), face_slots_by_receiver_.view, sum, false,
                    stream_);
        add_product(sum, first_weight(mlp, p, block++), z);
      }
      const DeviceMatrix out = node_latents(next, set).view(count, l);
      mlp_forward(mlp, p, z, cache, out);
      add_into(node_latents(cur, set).get(), out);
    };
    if (object_nodes) update_nodes(NodeSet::kObject, step.object_node, c.object_node, objects_);
    update_nodes(NodeSet::kMesh, step.mesh_node, c.mesh_node, nodes_);
  }

  // 3. Decode accelerations, and bring them to the host.
  const DeviceMatrix output = output_.view(nodes_, 3);
  mlp_forward_dense(network_.decoder(), p, levels_[m % levels].mesh.get(), decoder_, output);
  host_output_.resize(size_t(nodes_) * 3);
  if (nodes_ > 0) {
    check(cudaMemcpyAsync(host_output_.data(), output.data, host_output_.size() * sizeof(float),
                          cudaMemcpyDeviceToHost, stream_),
          "cudaMemcpyAsync (output)");
  }
  check(cudaStreamSynchronize(stream_), "forward");
  forward_seconds_ += seconds_since(start);
  return {host_output_.data(), nodes_, 3};
}

void CudaBackend::backward(const float* params, float* grads, const Graph& graph,
                           const ConstMatrixRef& d_output) {
  const ModelConfig& config = network_.config();
  const int l = config.latent_size, m = config.message_passing_steps;
  const int kinds = static_cast<int>(network_.edge_kinds().size());
  const bool face_edges = network_.face_edges(), object_nodes = config.graph.object_nodes;
  if (d_output.rows() != nodes_ || graph.num_mesh_nodes() != nodes_) {
    throw ConfigError(fmt::format(
        "CUDA backward: d_output has {} rows and the graph {} nodes; the last forward had {}",
        d_output.rows(), graph.num_mesh_nodes(), nodes_));
  }
  const auto start = std::chrono::steady_clock::now();
  ++backward_calls_;
  upload_parameters(params);
  const float* p = params_.data();
  const size_t count = network_.layout().size();
  float* g = grads_.reserve(count);
  check(cudaMemsetAsync(g, 0, count * sizeof(float), stream_), "cudaMemsetAsync (gradients)");
  const RowMatrixXf d_host = d_output;  // contiguous for the copy
  const DeviceMatrix d_top_output = d_output_.view(nodes_, 3);
  check(cudaMemcpyAsync(d_top_output.data, d_host.data(), d_host.size() * sizeof(float),
                        cudaMemcpyHostToDevice, stream_),
        "cudaMemcpyAsync (d_output)");

  Level* g_next = &grads_levels_[0];  // gradients of the level after the step being undone
  Level* g_cur = &grads_levels_[1];
  for (Level* level : {g_next, g_cur}) level->edges.resize(kinds);
  g_next->mesh.zeros(nodes_, l, stream_);
  g_next->object.zeros(objects_, l, stream_);
  g_next->face.zeros(faces_, 3 * l, stream_);
  for (int t = 0; t < kinds; ++t) g_next->edges[t].zeros(edges_[t].count, l, stream_);
  const DeviceMatrix d_top = g_next->mesh.get();
  mlp_backward_dense(network_.decoder(), p, g, levels_[m].mesh.get(), d_top_output, decoder_,
                     &d_top);

  for (int k = m - 1; k >= 0; --k) {
    const Network::Step& step = network_.step(k);
    Level& cur = levels_[k];
    StepCache& c = steps_[k];
    // Residuals pass node gradients straight through.
    copy(g_next->mesh.get(), g_cur->mesh.view(nodes_, l));
    copy(g_next->object.get(), g_cur->object.view(objects_, l));
    // Node updates: into the old node latents and the new edge latents.
    auto undo_node_update = [&](NodeSet set, const Mlp& mlp, MlpCache& cache, int count) {
      mlp_backward(mlp, p, g, node_latents(*g_next, set).get(), cache);
      const DeviceMatrix d_first = cache.d_first.get();
      const DeviceMatrix d_old = node_latents(*g_cur, set).get();
      backprop_product(node_latents(cur, set).get(), first_weight(mlp, p, 0), d_first,
                       first_weight(mlp, g, 0), &d_old);
      int block = 1;
      for (int t = 0; t < kinds; ++t) {
        if (network_.receiver_set(t) != set) continue;
        const DeviceMatrix d_sum = d_aggregate_.zeros(count, l, stream_);
        backprop_product(c.aggregates[t].get(), first_weight(mlp, p, block), d_first,
                         first_weight(mlp, g, block), &d_sum);
        ++block;
        gather_add(d_sum, {edges_[t].receivers.data(), edges_[t].count, 1, 0},
                   g_next->edges[t].get(), stream_);
      }
      if (set == NodeSet::kMesh && face_edges) {
        const DeviceMatrix d_sum = d_aggregate_.zeros(count, l, stream_);
        backprop_product(c.face_aggregate.get(), first_weight(mlp, p, block), d_first,
                         first_weight(mlp, g, block), &d_sum);
        ++block;
        gather_add(d_sum, {face_receivers_.data(), 3 * faces_, 1, 0},
                   as_face_slots(g_next->face.get(), l), stream_);
      }
    };
    undo_node_update(NodeSet::kMesh, step.mesh_node, c.mesh_node, nodes_);
    if (object_nodes) undo_node_update(NodeSet::kObject, step.object_node, c.object_node, objects_);
    // Edge gradients are now complete for this level; residuals pass them through.
    for (int t = 0; t < kinds; ++t) {
      copy(g_next->edges[t].get(), g_cur->edges[t].view(edges_[t].count, l));
    }
    copy(g_next->face.get(), g_cur->face.view(faces_, 3 * l));
    // Edge updates: into the old edge latents and both endpoints' old node latents.
    for (int t = 0; t < kinds; ++t) {
      const DeviceEdges& edges = edges_[t];
      const Mlp& mlp = step.edges[t];
      mlp_backward(mlp, p, g, g_next->edges[t].get(), c.edges[t]);
      const DeviceMatrix d_first = c.edges[t].d_first.get();
      const DeviceMatrix d_edges = g_cur->edges[t].get();
      backprop_product(cur.edges[t].get(), first_weight(mlp, p, 0), d_first,
                       first_weight(mlp, g, 0), &d_edges);
      const NodeSet senders = network_.sender_set(t), receivers = network_.receiver_set(t);
      const DeviceMatrix d_senders = node_latents(*g_cur, senders).get();
      backprop_gathered_product(node_latents(cur, senders).get(), first_weight(mlp, p, 1),
                                edges.by_sender.view, edges.count, d_first, first_weight(mlp, g, 1),
                                &d_senders);
      const DeviceMatrix d_receivers = node_latents(*g_cur, receivers).get();
      backprop_gathered_product(node_latents(cur, receivers).get(), first_weight(mlp, p, 2),
                                edges.by_receiver.view, edges.count, d_first,
                                first_weight(mlp, g, 2), &d_receivers);
    }
    if (face_edges) {
      const Mlp& mlp = step.face;
      mlp_backward(mlp, p, g, g_next->face.get(), c.face);
      const DeviceMatrix d_first = c.face.d_first.get();
      const DeviceMatrix q = cur.face.get(), d_q = g_cur->face.get(), d_mesh = g_cur->mesh.get();
      for (int j = 0; j < 3; ++j) {
        const DeviceMatrix d_qj = d_q.columns(j * l, l);
        backprop_product(q.columns(j * l, l), first_weight(mlp, p, 3 * j), d_first,
                         first_weight(mlp, g, 3 * j), &d_qj);
        backprop_gathered_product(cur.mesh.get(), first_weight(mlp, p, 3 * j + 1),
                                  face_by_sender_[j].view, faces_, d_first,
                                  first_weight(mlp, g, 3 * j + 1), &d_mesh);
        backprop_gathered_product(cur.mesh.get(), first_weight(mlp, p, 3 * j + 2),
                                  face_by_receiver_[j].view, faces_, d_first,
                                  first_weight(mlp, g, 3 * j + 2), &d_mesh);
      }
    }
    std::swap(g_next, g_cur);
  }

  // Encoders: parameter gradients only (inputs are data).
  mlp_backward_dense(network_.mesh_node_encoder(), p, g, in_mesh_.get(), g_next->mesh.get(),
                     encode_mesh_, nullptr);
  if (object_nodes) {
    mlp_backward_dense(network_.object_node_encoder(), p, g, in_object_.get(), g_next->object.get(),
                       encode_object_, nullptr);
  }
  for (int t = 0; t < kinds; ++t) {
    mlp_backward_dense(network_.edge_encoder(t), p, g, in_edges_[t].get(), g_next->edges[t].get(),
                       encode_edges_[t], nullptr);
  }
  if (face_edges) {
    mlp_backward_dense(network_.face_encoder(), p, g, in_face_.get(), g_next->face.get(),
                       encode_face_, nullptr);
  }
  // Accumulate into the caller's host gradients, as the CPU path does.
  host_grads_.resize(count);
  check(cudaMemcpyAsync(host_grads_.data(), g, count * sizeof(float), cudaMemcpyDeviceToHost,
                        stream_),
        "cudaMemcpyAsync (gradients)");
  check(cudaStreamSynchronize(stream_), "backward");
  for (size_t i = 0; i < count; ++i) grads[i] += host_grads_[i];
  backward_seconds_ += seconds_since(start);
}

}  // namespace

int device_count() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no driver" error
    return 0;
  }
  return count;
}

std::string describe_device(int device) {
  cudaDeviceProp properties{};
  check(cudaGetDeviceProperties(&properties, device), "cudaGetDeviceProperties");
  return fmt::format("{} (sm_{}{}, {:.1f} GiB)", properties.name, properties.major,
                     properties.minor, properties.totalGlobalMem / double(1 << 30));
}

std::unique_ptr<NetworkBackend> make_cuda_backend(const Network& network,
                                                  const CudaOptions& options) {
  return std::make_unique<CudaBackend>(network, options);
}

}  // namespace fignet::cuda
