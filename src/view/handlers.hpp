// The endpoints of the view's API (docs/view.md, "API"), each a function of the catalog and the
// request. They throw RequestError (a 4xx with its message) for a bad request; Api::handle()
// turns that and the library's own exceptions into responses.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <string_view>

#include "catalog.hpp"
#include "halfback/view/api.hpp"

namespace halfback::view {

// The time a request's computation may take, and whether its answer is still wanted: a long
// computation polls expired() between its parts (a fit before each evaluation of a term) and
// gives up with check() once it is.
class Budget {
 public:
  // `abandoned` (may be empty) and `stopping` as Request::abandoned and Api::stop().
  Budget(double seconds, const std::function<bool()>& abandoned, const std::atomic<bool>& stopping);
  // Past the deadline, abandoned by the client, or the server stops.
  bool expired() const;
  // Seconds to the deadline (0 when past it).
  double seconds_left() const;
  // Throws RequestError 503 saying which of the three ended `what` ("the fit"), if expired().
  void check(std::string_view what) const;

 private:
  double seconds_;
  std::chrono::steady_clock::time_point deadline_;
  const std::function<bool()>& abandoned_;
  const std::atomic<bool>& stopping_;
};

Response info_response(const Catalog& catalog);
Response brdf_response(const Catalog& catalog, const Request& request);
Response slices_response(const Catalog& catalog, const Request& request, int threads,
                         const Budget& budget);
Response hemisphere_response(const Catalog& catalog, const Request& request, int threads,
                             const Budget& budget);
Response polar_response(const Catalog& catalog, const Request& request);
Response albedo_response(const Catalog& catalog, const Request& request, int threads,
                         const Budget& budget);
Response point_response(const Catalog& catalog, const Request& request);
Response render_response(const Catalog& catalog, const Request& request, int threads,
                         const Budget& budget);
Response point_light_response(const Catalog& catalog, const Request& request, int threads,
                              const Budget& budget);
Response mesh_response(const Catalog& catalog, const Request& request, int threads,
                       const Budget& budget);
// `running` counts the fits in progress: a request made while one runs is answered 503.
// A fit of more than kMaxFitTermSamples terms × samples is a 400.
Response fit_response(const Catalog& catalog, const Request& request, int threads,
                      std::atomic<int>& running, const Budget& budget);

}  // namespace halfback::view
