// prast-diff's flags; see diff_flags.h.
#include "apps/cli/diff_flags.h"

#include <cmath>

#include "apps/cli/flags.h"
#include "apps/cli/values.h"

namespace prast::cli {

namespace {

void add_diff_flags(FlagSet& set, DiffOptions& o) {
    Flag& help = set.toggle({"-h", "--help"}, "this text", [&o] { o.help = true; });
    help.stops = true;
    help.help = "Prints the flags and exits (exit code 0).";
    Flag& version = set.toggle({"--version"}, "the version", [&o] { o.version = true; });
    version.stops = true;
    version.help = "Prints the version and exits.";
    Flag& t = set.value({"--tolerance"}, "T", "a channel may differ by up to T (8-bit units, 0..255; default 0)", "0",
                        {"256", "-1", "1.5"}, [&o](const std::string& flag, const std::string& v) {
                            long n;
                            if (!parse_integer_in(v, 0, 255, n)) bad_value(flag, v, "expected an integer from 0 to 255");
                            o.tol.channel = int(n);
                        });
    t.help = "A channel may differ by up to T (8-bit units, 0 to 255) and still count as equal.";
    t.hints = {"tol", "threshold", "epsilon", "delta", "max-diff"};
    Flag& f = set.value({"--max-fraction"}, "F", "at most floor(F * pixels) pixels may exceed T (0..1; default 0)",
                        "0", {"1.5", "nan", ""}, [&o](const std::string& flag, const std::string& v) {
                            double d;
                            if (!parse_finite(v, d) || d < 0.0 || d > 1.0)
                                bad_value(flag, v, "expected a number from 0 to 1");
                            o.tol.fraction = d;
                        });
    f.help = "At most floor(F * pixels) pixels may exceed the tolerance (0 to 1) for a match.";
    f.hints = {"fraction", "max-pixels", "allowed", "ratio"};
    Flag& h = set.value({"--heatmap"}, "OUT.png", "write where the images differ", "", {""},
                        [&o](const std::string& flag, const std::string& v) {
                            if (v.empty()) fail(flag + " needs a file name");
                            o.heatmap = v;
                        });
    h.help = "Writes where the images differ: grey = equal (image A dimmed), blue = within T, red to yellow = "
             "beyond T; the green channel is the difference.";
    h.hints = {"heat-map", "diff-image", "output", "out"};
    set.positional("A.png B.png", "the two 8-bit images (PNG, or any format stb_image reads; 16-bit keeps the high "
                                  "byte; not .hdr)");
}

std::vector<HelpRow> diff_rows() {
    return {{{"--tolerance"}, "a channel may differ by up to T (8-bit units, 0..255; default 0)"},
            {{"--max-fraction"}, "at most floor(F * pixels) pixels may exceed T (0..1; default 0)"},
            {{"--heatmap"}, "write where the images differ: grey = equal (image A dimmed),\n"
                            "blue = within T, red to yellow = beyond T; green = the difference"},
            {{"--help", "--version"}, ""}};
}

std::string missing_value(const std::string& flag, const std::string&) { return flag + " needs a value"; }

} // namespace

std::string parse_diff_args(int argc, const char* const* argv, DiffOptions& out) {
    FlagSet set("prast-diff");
    set.missing = missing_value;
    add_diff_flags(set, out);
    std::string err = set.parse(argc, argv, out.files);
    if (!err.empty() || out.help || out.version) return err;
    if (out.files.size() != 2) return "expected two images, got " + std::to_string(out.files.size());
    return "";
}

const char* diff_usage() {
    static const std::string text = [] {
        DiffOptions o;
        FlagSet set("prast-diff");
        add_diff_flags(set, o);
        return set.usage("usage: prast-diff A.png B.png [--tolerance T] [--max-fraction F] [--heatmap OUT.png]\n",
                         diff_rows(),
                         "prints psnr, the largest difference, the differing pixels and their bounding box\n"
                         "exit codes: 0 match, 1 differ (or sizes differ), 2 bad usage or unreadable image\n",
                         21);
    }();
    return text.c_str();
}

std::vector<Flag> diff_flag_list() {
    DiffOptions o;
    FlagSet set("prast-diff");
    add_diff_flags(set, o);
    return set.flags();
}

std::string diff_markdown() {
    DiffOptions o;
    FlagSet set("prast-diff");
    add_diff_flags(set, o);
    return set.markdown("prast-diff A.png B.png [options]",
                        "Compares two 8-bit images for pixel tests and prints PSNR, the largest difference, the "
                        "differing pixels and their bounding box. Exit codes: 0 match, 1 differ (also when the "
                        "sizes differ), 2 bad usage or an unreadable image.");
}

} // namespace prast::cli
