// The endpoints of the view's API (docs/view.md, "API"), each a function of the catalog and the
// request. They throw RequestError (a 4xx with its message) for a bad request; Api::handle()
// turns that and the library's own exceptions into responses.
#pragma once

#include <atomic>

#include "catalog.hpp"
#include "halfback/view/api.hpp"

namespace halfback::view {

Response info_response(const Catalog& catalog);
Response brdf_response(const Catalog& catalog, const Request& request);
Response slices_response(const Catalog& catalog, const Request& request, int threads);
Response hemisphere_response(const Catalog& catalog, const Request& request, int threads);
Response polar_response(const Catalog& catalog, const Request& request);
Response albedo_response(const Catalog& catalog, const Request& request, int threads);
Response point_response(const Catalog& catalog, const Request& request);
Response render_response(const Catalog& catalog, const Request& request, int threads);
Response point_light_response(const Catalog& catalog, const Request& request, int threads);
// `running` counts the fits in progress: a request made while one runs is answered 503.
Response fit_response(const Catalog& catalog, const Request& request, int threads,
                      std::atomic<int>& running);

}  // namespace halfback::view
