// The HTML report of a record (record/reader.h): one self-contained page (script, styles and data
// inlined; it makes no network request) with a top-down replay, plots over time, per-cycle cost
// tables and the drive's summary. See src/report/web/ for the page itself.
#pragma once

#include <string>
#include <string_view>

#include "frenetic/record/reader.h"
#include "frenetic/status.h"

namespace frenetic::report {

// The data the page reads, as compact JSON (format "frenetic-report", version 1): per-exchange
// columns with rounded numbers (positions 0.01 m, path and traffic 0.1 m, costs 4 significant
// digits), ragged arrays with offsets, candidates for the kept cycles. NaN becomes null.
// `source` names the record in the page.
std::string PageDataJson(const record::RunData& run, std::string_view source);

// The complete HTML page for `run`.
std::string RenderPage(const record::RunData& run, std::string_view source);

// The page's assets as built into the library (for tests): the HTML template with its style and
// script inlined and one data placeholder left. One template for every run: the script draws a
// CommonRoad run's parts (the road's lanes, goal regions, cars of their own sizes, the verdict,
// the planner's speed cap) when the data's header says world "commonroad", a drive's otherwise.
std::string_view PageTemplate();

// Writes `content` to `path` (replacing it); an error names the path when it cannot be written.
Status WriteFile(const std::string& path, std::string_view content);

}  // namespace frenetic::report
