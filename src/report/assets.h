// The page's web assets (src/report/web/), embedded at build time by report.cmake.
#pragma once

#include <string_view>

namespace frenetic::report::internal {

// report.html with report.css and report.js inlined; "@FRENETIC_DATA@" marks where the data goes.
std::string_view PageTemplateText();

}  // namespace frenetic::report::internal
