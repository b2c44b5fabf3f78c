// One contact pair through hbm::ContactEvaluator: residual, analytic Jacobian and central
// finite-difference Jacobian, per model/update and across H and N; and many pairs threaded.
// Goals (BENCHMARKS.md): analytic Jacobian <= 5 residuals, >= 10x faster than central FD.
// Arguments: model (0 full3d, 1 quasi3d, 2 1d), update (0 radial_return, 1 exact_linear), H, N.
#include <benchmark/benchmark.h>

#include <random>

#include "contact_test_support.hpp"
#include "hbm/contact_evaluator.hpp"

namespace {

using namespace shroudsim;

const contact::PairParameters kPair{
    .tangential_stiffness = 2e5, .normal_stiffness = 5e5, .friction_coefficient = 0.4, .normal_preload = 3.0};

struct Setup {
  std::unique_ptr<hbm::ContactEvaluator> ev;
  Eigen::VectorXd w, f;
  std::vector<Eigen::MatrixXd> j;
};

Setup make(const benchmark::State& state, int pairs = 1, int threads = 1) {
  hbm::ContactEvaluatorOptions o;
  const contact::Model models[] = {contact::Model::full3d, contact::Model::quasi3d, contact::Model::one_d};
  o.law.model = models[state.range(0)];
  o.law.update = state.range(1) == 0 ? contact::TangentialUpdate::radial_return
                                     : contact::TangentialUpdate::exact_linear;
  o.n_harmonics = static_cast<int>(state.range(2));
  o.n_time_samples = static_cast<int>(state.range(3));
  o.threads = threads;
  Setup s;
  s.ev = std::make_unique<hbm::ContactEvaluator>(o, std::vector<contact::PairParameters>(pairs, kPair));
  std::mt19937 rng(42);
  const int n = s.ev->pair_layout().size();
  s.w.resize(s.ev->size());
  for (int p = 0; p < pairs; ++p)
    s.w.segment(p * n, n) = testing::random_contact_state(s.ev->pair_layout(), kPair, rng);
  return s;
}

void label(benchmark::State& state, const Setup& s) {
  state.SetLabel(contact::to_string(s.ev->options().law.model) + "/" + contact::to_string(s.ev->options().law.update));
}

void BM_Residual(benchmark::State& state) {
  Setup s = make(state);
  for (auto _ : state) {
    s.ev->evaluate(s.w, s.f, nullptr);
    benchmark::DoNotOptimize(s.f.data());
  }
  label(state, s);
}

void BM_AnalyticJacobian(benchmark::State& state) {
  Setup s = make(state);
  for (auto _ : state) {
    s.ev->evaluate(s.w, s.f, &s.j, hbm::JacobianMethod::analytic);
    benchmark::DoNotOptimize(s.j[0].data());
  }
  label(state, s);
}

void BM_FiniteDifferenceJacobian(benchmark::State& state) {
  Setup s = make(state);
  for (auto _ : state) {
    s.ev->evaluate(s.w, s.f, &s.j, hbm::JacobianMethod::finite_difference);
    benchmark::DoNotOptimize(s.j[0].data());
  }
  label(state, s);
}

// 50 pairs, analytic Jacobian, 1 or 2 threads (last argument).
void BM_FiftyPairsAnalytic(benchmark::State& state) {
  Setup s = make(state, 50, static_cast<int>(state.range(4)));
  for (auto _ : state) {
    s.ev->evaluate(s.w, s.f, &s.j, hbm::JacobianMethod::analytic);
    benchmark::DoNotOptimize(s.j[0].data());
  }
  label(state, s);
}

void per_model(benchmark::internal::Benchmark* b) {
  for (int model : {0, 1, 2})
    for (int update : {0, 1}) b->Args({model, update, 5, 512});
  for (int h : {1, 5, 15})
    for (int n : {64, 512, 2048})
      if (!(h == 5 && n == 512)) b->Args({0, 1, h, n});
  b->Args({0, 1, 50, 512});
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(BM_Residual)->Apply(per_model);
BENCHMARK(BM_AnalyticJacobian)->Apply(per_model);
BENCHMARK(BM_FiniteDifferenceJacobian)->Apply(per_model);
BENCHMARK(BM_FiftyPairsAnalytic)
    ->Args({0, 1, 5, 512, 1})
    ->Args({0, 1, 5, 512, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_MAIN();
