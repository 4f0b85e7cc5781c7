// Fuzz target: the restricted pickle reader (io/pickle.hpp). A pickle that reads is walked
// (a bounded number of values: pickles may refer to themselves) through the accessors.

#include <vector>

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "io/pickle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.pkl";
  io::PickleLimits limits;
  limits.max_values = 1u << 16;
  try {
    const io::Pickle pickle = io::Pickle::parse(fuzz::text(data, size), name, limits);
    std::vector<io::Pickle::Value> todo{pickle.root()};
    for (int budget = 10000; !todo.empty() && budget > 0; --budget) {
      const io::Pickle::Value v = todo.back();
      todo.pop_back();
      switch (v.kind()) {
        case io::Pickle::Kind::list:
        case io::Pickle::Kind::tuple:
          for (std::size_t i = 0; i < v.size() && i < 100; ++i) todo.push_back(v[i]);
          break;
        case io::Pickle::Kind::dict:
          for (std::size_t i = 0; i < v.dict_size() && i < 100; ++i) {
            todo.push_back(v.key(i));
            todo.push_back(v.value(i));
          }
          break;
        case io::Pickle::Kind::array:
          if (v.array().dtype == io::DType::object) {
            for (std::size_t i = 0; i < v.size() && i < 100; ++i) todo.push_back(v[i]);
          } else {
            (void)v.array().to_doubles();
          }
          break;
        case io::Pickle::Kind::integer:
        case io::Pickle::Kind::real:
          (void)v.as_real();
          break;
        case io::Pickle::Kind::string:
        case io::Pickle::Kind::bytes:
          (void)v.as_string();
          break;
        default:
          break;
      }
    }
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
