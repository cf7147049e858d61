// A fixture of the layer check: a render test including loader, which the graph's "render tests"
// line allows (the check must not complain about it).
#include "halfback/loader/load.hpp"
