// The contract's types as other vendors see them: every struct in idl/dh3.idl
// is final. Another vendor's IDL compiler gives a struct that declares no
// extensibility whatever its default is (appendable in some), and an appendable
// type travels as XCDR2, which dh3's participants do not read. The structs are
// read from the IDL text itself, so a struct added later is checked too, and
// their extensibility from the TypeObjects fastddsgen makes of that text, so
// an annotation fastddsgen does not understand fails here as well.

#include <gtest/gtest.h>

#include <fastrtps/types/TypeObjectFactory.h>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dh3TypeObject.h"

namespace {

using eprosima::fastrtps::types::TypeObject;
using eprosima::fastrtps::types::TypeObjectFactory;

// Plain string scanning, not <regex>: GCC 12's regex headers trip
// -Wmaybe-uninitialized (an error here) in the sanitizer builds.
std::string without_comments(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    if (text.compare(i, 2, "//") == 0) {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (text.compare(i, 2, "/*") == 0) {
      const std::size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 2;
      out += ' ';
    } else {
      out += text[i++];
    }
  }
  return out;
}

bool is_word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

/// Fully qualified names ("dh3::msg::HandStatus") of the structs the IDL declares.
std::vector<std::string> structs_declared_in(const std::string& idl) {
  const std::string text = without_comments(idl);
  std::vector<std::string> scope;  // "" for braces that name no module or struct
  std::vector<std::string> found;
  auto skip_space = [&text](std::size_t i) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i])) != 0) ++i;
    return i;
  };
  for (std::size_t i = 0; i < text.size();) {
    if (text[i] == '{') {
      scope.emplace_back();
      ++i;
    } else if (text[i] == '}') {
      if (!scope.empty()) scope.pop_back();
      ++i;
    } else if (is_word_char(text[i])) {
      std::size_t end = i;
      while (end < text.size() && is_word_char(text[end])) ++end;
      const std::string word = text.substr(i, end - i);
      i = end;
      if (word != "module" && word != "struct") continue;
      const std::size_t name_at = skip_space(i);
      std::size_t name_end = name_at;
      while (name_end < text.size() && is_word_char(text[name_end])) ++name_end;
      const std::size_t brace = skip_space(name_end);
      if (name_end == name_at || brace >= text.size() || text[brace] != '{') continue;
      const std::string name = text.substr(name_at, name_end - name_at);
      std::string qualified;
      for (const auto& part : scope) {
        if (!part.empty()) qualified += part + "::";
      }
      if (word == "struct") found.push_back(qualified + name);
      scope.push_back(name);
      i = brace + 1;
    } else {
      ++i;
    }
  }
  return found;
}

std::string read_file(const char* path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ContractTypes, TheParserFindsNestedStructsAndSkipsComments) {
  const auto names = structs_declared_in(
      "module a { // struct Commented { }\n module b { struct S { long x; }; };\n"
      " /* struct Hidden { }; */ struct T { string s; }; enum E { X, Y }; };");
  EXPECT_EQ(names, (std::vector<std::string>{"a::b::S", "a::T"}));
}

TEST(ContractTypes, EveryStructOfTheContractIsFinal) {
  const std::string idl = read_file(DH3_CONTRACT_IDL);
  ASSERT_FALSE(idl.empty()) << "cannot read " << DH3_CONTRACT_IDL;
  const auto names = structs_declared_in(idl);
  // The contract has eight structs today; fewer means the parser lost some.
  ASSERT_GE(names.size(), 8u);

  registerdh3Types();
  for (const auto& name : names) {
    SCOPED_TRACE(name);
    for (const bool complete : {true, false}) {
      const TypeObject* type = TypeObjectFactory::get_instance()->get_type_object(name, complete);
      ASSERT_NE(type, nullptr) << "fastddsgen made no TypeObject for it";
      const auto& flags = complete ? type->complete().struct_type().struct_flags()
                                   : type->minimal().struct_type().struct_flags();
      EXPECT_TRUE(flags.IS_FINAL()) << name << " is not @final";
      EXPECT_FALSE(flags.IS_APPENDABLE());
      EXPECT_FALSE(flags.IS_MUTABLE());
    }
  }
}

}  // namespace
