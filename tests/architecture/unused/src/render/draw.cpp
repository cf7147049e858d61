// A fixture of the layer check: render's library includes brdf but not util, which the graph's
// render line names (the check must say so).
#include "halfback/brdf/brdf.hpp"
