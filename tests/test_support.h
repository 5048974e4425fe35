#pragma once
#include <string>
std::string testScratchDir(const std::string& name);
