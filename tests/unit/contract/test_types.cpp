// The contract's types as other vendors see them: every struct in idl/dh3.idl
// is final. Another vendor's IDL compiler gives a struct that declares no
// extensibility whatever its default is (appendable in some), and an appendable
// type travels as XCDR2, which dh3's participants do not read. The structs are
// read from the IDL text itself, so a struct added later is checked too, and
// their extensibility from the TypeObjects fastddsgen makes of that text, so
// an annotation fastddsgen does not understand fails here as well.

#include <gtest/gtest.h>

#include <fastrtps/types/TypeObjectFactory.h>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "dh3TypeObject.h"

namespace {

using eprosima::fastrtps::types::TypeObject;
using eprosima::fastrtps::types::TypeObjectFactory;

std::string without_comments(const std::string& text) {
  static const std::regex kComment(R"(//[^\n]*|/\*[\s\S]*?\*/)");
  return std::regex_replace(text, kComment, " ");
}

/// Fully qualified names ("dh3::msg::HandStatus") of the structs the IDL declares.
std::vector<std::string> structs_declared_in(const std::string& idl) {
  static const std::regex kToken(R"(\b(module|struct)\s+(\w+)\s*\{|\{|\})");
  std::vector<std::string> scope;  // "" for braces that name no module or struct
  std::vector<std::string> found;
  const std::string text = without_comments(idl);
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kToken);
       it != std::sregex_iterator(); ++it) {
    const std::smatch& token = *it;
    if (token.str(0) == "}") {
      if (!scope.empty()) scope.pop_back();
      continue;
    }
    if (token.str(1).empty()) {
      scope.emplace_back();
      continue;
    }
    std::string name;
    for (const auto& part : scope) {
      if (!part.empty()) name += part + "::";
    }
    name += token.str(2);
    if (token.str(1) == "struct") found.push_back(name);
    scope.push_back(token.str(2));
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
