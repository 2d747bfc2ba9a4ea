#pragma once
// `frostmpm plugins` and `frostmpm describe`: both read the registry, and the Markdown form of
// describe is the generated config reference in docs/.
#include <iosfwd>
#include <string>
#include <vector>

namespace frostmpm::app {
int cmd_plugins(const std::vector<std::string>& extra_paths, std::ostream& out);
int cmd_describe(const std::string& target, bool markdown, const std::vector<std::string>& extra_paths,
                 std::ostream& out);
}  // namespace frostmpm::app
