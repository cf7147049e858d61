// Writes the Python module's type stubs from their template at build time, with the names of the
// coordinate spaces taken from the parameterization list (so that adding a parameterization needs
// no edit of the stubs).
//   halfback_stubgen TEMPLATE OUTPUT
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "halfback/core/space.hpp"

namespace {

std::string quoted_space_names() {
  std::string names = "\"dirs\"";
  for (halfback::Space s : halfback::parameterizations())
    names += ", \"" + std::string(halfback::name_of(s)) + "\"";
  return names;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: halfback_stubgen TEMPLATE OUTPUT\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::string key = "@PARAMETERIZATION_NAMES@";
  const auto at = s.find(key);
  if (!in || at == std::string::npos) {
    std::cerr << "halfback_stubgen: " << argv[1] << " is unreadable or has no " << key << "\n";
    return 1;
  }
  s.replace(at, key.size(), quoted_space_names());
  std::ofstream out(argv[2]);
  out << s;
  return out.good() ? 0 : 1;
}
