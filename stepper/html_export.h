// `step --out DIR`: every stage image as DIR/NAME.png and DIR/index.html,
// which shows them with a sentence or two each. Plain files: the page opens
// offline in any browser.
#pragma once

#include <string>

#include "stepper/recording.h"

namespace prast::stepper {

// Writes the stages and the page; returns "" or a one-line error naming the file.
std::string export_html(FrameSetup& s, const Recording& rec, const std::string& dir);

// Text with &, <, >, " escaped for HTML.
std::string html_escape(const std::string& s);

} // namespace prast::stepper
