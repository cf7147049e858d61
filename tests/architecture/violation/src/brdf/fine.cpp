// A fixture of the layer check: an include the graph allows.
#include "halfback/core/param.hpp"
