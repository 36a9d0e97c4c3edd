// Passes of concurrent calls batched into one forward (model/pass_batcher.h).
#include "model/pass_batcher.h"

#include <torch/torch.h>

#include <stdexcept>
#include <thread>
#include <vector>

#include "gtest/gtest.h"
#include "model/pass_batching.h"

namespace stylus::model {
namespace {

using namespace std::chrono_literals;

// Doubles each row and adds the number of rows the pass saw in its last
// column, so a caller can tell whether its rows ran with others'.
torch::Tensor Twice(const std::vector<torch::Tensor>& in) {
  torch::Tensor out = in[0] * 2;
  out.select(1, 2).fill_(static_cast<float>(in[0].size(0)));
  return out;
}

TEST(PassBatcherTest, ConcurrentCallsRunAsOnePassAndEachGetsItsRows) {
  PassBatcher batcher(/*max_rows=*/5, 10s);  // Fills with both calls: no waiting for the delay.
  const int owner = 0;
  const torch::Tensor a = torch::arange(6, torch::kFloat32).reshape({2, 3});
  const torch::Tensor b = torch::arange(100, 109, torch::kFloat32).reshape({3, 3});
  torch::Tensor out_a, out_b;
  std::thread ta([&] { out_a = RunPass(&batcher, &owner, 1, {a}, Twice); });
  std::thread tb([&] { out_b = RunPass(&batcher, &owner, 1, {b}, Twice); });
  ta.join();
  tb.join();
  ASSERT_EQ(out_a.size(0), 2);
  ASSERT_EQ(out_b.size(0), 3);
  EXPECT_TRUE(torch::equal(out_a.slice(1, 0, 2), a.slice(1, 0, 2) * 2));
  EXPECT_TRUE(torch::equal(out_b.slice(1, 0, 2), b.slice(1, 0, 2) * 2));
  EXPECT_EQ(out_a[0][2].item<float>(), 5) << "one pass saw both calls' rows";
  EXPECT_EQ(out_b[0][2].item<float>(), 5);
  EXPECT_EQ(batcher.batches(), 1);
  EXPECT_EQ(batcher.calls(), 2);
}

TEST(PassBatcherTest, OtherModelsPassesOrShapesDoNotJoin) {
  PassBatcher batcher(/*max_rows=*/4, 50ms);
  const int m1 = 0, m2 = 0;
  const torch::Tensor two = torch::ones({2, 3}), wide = torch::ones({2, 4});
  std::vector<torch::Tensor> outs(4);
  std::vector<std::thread> threads;
  threads.emplace_back([&] { outs[0] = RunPass(&batcher, &m1, 1, {two}, Twice); });
  threads.emplace_back([&] { outs[1] = RunPass(&batcher, &m2, 1, {two}, Twice); });
  threads.emplace_back([&] { outs[2] = RunPass(&batcher, &m1, 2, {two}, Twice); });
  threads.emplace_back([&] { outs[3] = RunPass(&batcher, &m1, 1, {wide}, Twice); });
  for (auto& t : threads) t.join();
  for (const torch::Tensor& o : outs) EXPECT_EQ(o[0][2].item<float>(), 2) << "ran alone";
  EXPECT_EQ(batcher.batches(), 0);
}

TEST(PassBatcherTest, ACallOverTheLimitRunsAloneAtOnce) {
  PassBatcher batcher(/*max_rows=*/2, 10s);
  const int owner = 0;
  const auto start = std::chrono::steady_clock::now();
  const torch::Tensor out = RunPass(&batcher, &owner, 1, {torch::ones({3, 3})}, Twice);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s) << "did not wait for the delay";
  EXPECT_EQ(out.size(0), 3);
}

TEST(PassBatcherTest, APassErrorReachesEveryCallInTheBatch) {
  PassBatcher batcher(/*max_rows=*/2, 10s);
  const int owner = 0;
  auto failing = [](const std::vector<torch::Tensor>&) -> torch::Tensor {
    throw std::runtime_error("pass failed");
  };
  int errors = 0;
  std::mutex mu;
  auto call = [&] {
    try {
      RunPass(&batcher, &owner, 1, {torch::ones({1, 3})}, failing);
    } catch (const std::runtime_error& e) {
      std::lock_guard<std::mutex> lock(mu);
      if (std::string(e.what()) == "pass failed") ++errors;
    }
  };
  std::thread t1(call), t2(call);
  t1.join();
  t2.join();
  EXPECT_EQ(errors, 2);
  // The batcher still works afterwards.
  EXPECT_EQ(RunPass(&batcher, &owner, 1, {torch::ones({2, 3})}, Twice).size(0), 2);
}

TEST(PassBatcherTest, WithoutABatcherThePassRunsDirectly) {
  const int owner = 0;
  EXPECT_EQ(RunPass(nullptr, &owner, 1, {torch::ones({2, 3})}, Twice)[0][2].item<float>(), 2);
}

}  // namespace
}  // namespace stylus::model
