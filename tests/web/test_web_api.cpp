// dh3-web's API without a server or a service: how commands and bodies are
// parsed, the token and its file's mode, --listen, the Host names served,
// and HandApi's routing and refusals with a client on
// an empty domain (nothing may be sent for any of them).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "allowed_hosts.hpp"
#include "api_error.hpp"
#include "bearer_token.hpp"
#include "client_json.hpp"
#include "dh3/base/version.hpp"
#include "dh3/registers.hpp"
#include "event_stream.hpp"
#include "hand_api.hpp"
#include "support/test_domain.hpp"
#include "web_assets.hpp"
#include "web_command.hpp"
#include "web_options.hpp"

namespace dh3::web {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;

constexpr const char* kToken = "a-test-token-of-some-length";

ApiError refusal(std::string_view name, std::string_view body) {
  auto parsed = parse_web_command(name, body);
  EXPECT_FALSE(parsed.ok()) << name << " " << body;
  return parsed.ok() ? ApiError{} : parsed.error();
}

TEST(WebCommand, TakesTheBodiesOfDh3ctlsCommands) {
  auto move = parse_web_command("move", R"({"position": 30})");
  ASSERT_TRUE(move.ok());
  EXPECT_EQ(move->name, "move");
  EXPECT_EQ(move->value, 30);
  auto force = parse_web_command("force", R"({"closing": 60, "opening": 30})");
  ASSERT_TRUE(force.ok());
  EXPECT_EQ(force->value, 60);
  EXPECT_EQ(force->opening, 30);
  EXPECT_FALSE(parse_web_command("force", R"({"closing": 60})")->opening.has_value());
  EXPECT_TRUE(parse_web_command("init", "").ok());
  EXPECT_TRUE(parse_web_command("init", " {} ").ok());
  auto read = parse_web_command("read", R"({"register": "grip_status"})");
  ASSERT_TRUE(read.ok());
  EXPECT_EQ(read->register_code, reg::grip_status);
  EXPECT_TRUE(parse_web_command("set-can-id", R"({"can_id": 7, "confirm": true})").ok());
}

TEST(WebCommand, SaysWhatIsWrongWithABody) {
  const ApiError malformed = refusal("move", R"({"position": )");
  EXPECT_EQ(malformed.status, 400);
  EXPECT_EQ(malformed.code, "INVALID_ARGUMENT");
  EXPECT_THAT(malformed.message, HasSubstr("malformed JSON"));
  EXPECT_THAT(malformed.message, HasSubstr("column"));
  EXPECT_THAT(refusal("move", "[30]").message, HasSubstr("must be a JSON object, not array"));
  EXPECT_THAT(refusal("move", R"({"position": 30, "speed": 2})").message,
              HasSubstr("unknown field 'speed' for move (its fields: position)"));
  EXPECT_THAT(refusal("move", R"({"position": "30"})").message,
              HasSubstr("field 'position' of move must be an integer, not \"30\""));
  EXPECT_THAT(refusal("move", R"({"position": 30.5})").message, HasSubstr("must be an integer"));
  EXPECT_THAT(refusal("move", R"({"position": null})").message, HasSubstr("must be an integer"));
  EXPECT_THAT(refusal("move", "{}").message, HasSubstr("move needs the field 'position'"));
  EXPECT_THAT(refusal("move", R"({"position": 4294967396})").message, HasSubstr("out of range"));
  EXPECT_THAT(refusal("move", R"({"position": -4294967396})").message, HasSubstr("out of range"));
  EXPECT_THAT(refusal("read", R"({"register": "nonsense"})").message,
              HasSubstr("unknown register 'nonsense'"));
  EXPECT_THAT(refusal("set-can-id", R"({"can_id": 7})").message, HasSubstr("'confirm'"));
  EXPECT_THAT(refusal("set-can-id", R"({"can_id": 7, "confirm": false})").message,
              HasSubstr("\"confirm\": true"));
  const ApiError unknown = refusal("jump", "{}");
  EXPECT_EQ(unknown.status, 404);
  EXPECT_EQ(unknown.code, "UNKNOWN_COMMAND");
  EXPECT_THAT(unknown.message, HasSubstr("no command 'jump' (commands: init, move"));
}

TEST(WebCommand, TheOpenApiDescriptionListsEveryCommand) {
  const WebAsset* asset = find_asset("/api/openapi.json");
  ASSERT_NE(asset, nullptr);
  const auto doc = nlohmann::json::parse(asset->body, nullptr, false);
  ASSERT_FALSE(doc.is_discarded()) << "openapi.json is not JSON";
  const auto& parameters = doc["paths"]["/api/hands/{service}/{bus}/{id}/{command}"]["parameters"];
  std::set<std::string> described;
  for (const auto& parameter : parameters) {
    if (parameter["name"] == "command") {
      for (const auto& name : parameter["schema"]["enum"]) described.insert(name);
    }
  }
  std::set<std::string> shapes;
  for (const auto& shape : command_shapes()) shapes.insert(std::string(shape.name));
  EXPECT_EQ(described, shapes);
}

TEST(WebCommand, TheOpenApiDescriptionCarriesTheProjectVersion) {
  const WebAsset* asset = find_asset("/api/openapi.json");
  ASSERT_NE(asset, nullptr);
  const auto doc = nlohmann::json::parse(asset->body, nullptr, false);
  ASSERT_FALSE(doc.is_discarded()) << "openapi.json is not JSON";
  EXPECT_EQ(doc["info"]["version"], kVersion);
}

/// The openapi.json description's copy of the schema `name`.
const nlohmann::json& described_schema(const std::string& name) {
  static const nlohmann::json doc = [] {
    const WebAsset* asset = find_asset("/api/openapi.json");
    return asset == nullptr ? nlohmann::json::object()
                            : nlohmann::json::parse(asset->body, nullptr, false);
  }();
  static const nlohmann::json none = nlohmann::json::object();
  const auto& schemas = doc["components"]["schemas"];
  return schemas.contains(name) ? schemas[name] : none;
}

/// The schema a property's "$ref" (or its items' "$ref") names; null if none.
const nlohmann::json* referenced(const nlohmann::json& property) {
  const auto* ref = property.contains("$ref") ? &property["$ref"] : nullptr;
  if (ref == nullptr && property.contains("items") && property["items"].contains("$ref")) {
    ref = &property["items"]["$ref"];
  }
  if (ref == nullptr) return nullptr;
  const std::string prefix = "#/components/schemas/";
  return &described_schema(ref->get<std::string>().substr(prefix.size()));
}

/// Every member of `value` (the JSON a program prints) is a property of
/// `schema` and the other way round, down the referenced schemas.
void expect_same_fields(const nlohmann::json& schema, const nlohmann::json& value,
                        const std::string& where) {
  ASSERT_TRUE(value.is_object()) << where;
  std::set<std::string> printed;
  std::set<std::string> described;
  for (const auto& [key, member] : value.items()) printed.insert(key);
  for (const auto& [key, property] : schema["properties"].items()) described.insert(key);
  EXPECT_EQ(printed, described) << where << ": printed (left) and openapi.json (right)";
  for (const auto& [key, property] : schema["properties"].items()) {
    const nlohmann::json* inner = referenced(property);
    if (inner == nullptr || !value.contains(key)) continue;
    const auto& member = value[key];
    if (member.is_array()) {
      for (const auto& element : member) expect_same_fields(*inner, element, where + "." + key);
    } else {
      expect_same_fields(*inner, member, where + "." + key);
    }
  }
}

void expect_described_as(const std::string& name, const Json& printed) {
  ASSERT_TRUE(described_schema(name).contains("properties")) << name << " is not in openapi.json";
  expect_same_fields(described_schema(name), nlohmann::json::parse(json_text(printed)), name);
}

TEST(OpenApi, DescribesEveryFieldOfWhatTheApiPrints) {
  HandStatus status;
  status.address = {"cell", "bus0", 1};
  expect_described_as("Status", Json(status));
  HandEvent event;
  event.hand = status.address;
  expect_described_as("Event", Json(event));
  ServiceInfo info;
  info.buses.push_back(BusInfo{"bus0", "sim:1", true, {{1, "left"}}});
  expect_described_as("Service", Json(info));
  expect_described_as("Hands", Json{{"services", std::vector<ServiceInfo>{info}},
                                    {"hands", std::vector<HandStatus>{status}}});
  // A reply with every field a command may add.
  Reply reply;
  reply.grasp = GraspOutcome::grasped;
  reply.found_ids = {1};
  reply.lease_holder = "someone";
  expect_described_as("Reply", reply_json("grasp", "cell/bus0/1", reply));
  expect_described_as("Error", Json::parse(ApiError{400, "INVALID_ARGUMENT", "because"}.json()));
}

TEST(BearerToken, AcceptsOnlyTheExactToken) {
  const auto token = BearerToken::from_text(kToken);
  EXPECT_TRUE(token.accepts(std::string("Bearer ") + kToken));
  EXPECT_FALSE(token.accepts(""));
  EXPECT_FALSE(token.accepts(kToken));
  EXPECT_FALSE(token.accepts(std::string("Basic ") + kToken));
  EXPECT_FALSE(token.accepts(std::string("Bearer ") + kToken + "x"));
  EXPECT_FALSE(token.accepts("Bearer a-test-token-of-some-lengtX"));
  EXPECT_FALSE(token.accepts("Bearer a-test"));
}

TEST(BearerToken, RefusesAMissingEmptyOrShortFile) {
  const std::string path = "/tmp/dh3-web-token-" + std::to_string(::getpid());
  EXPECT_THAT(BearerToken::from_file(path).error(), HasSubstr("cannot read"));
  std::ofstream(path) << "\n";
  ::chmod(path.c_str(), 0600);
  EXPECT_THAT(BearerToken::from_file(path).error(), HasSubstr("empty"));
  std::ofstream(path) << "short\n";
  EXPECT_THAT(BearerToken::from_file(path).error(), HasSubstr("too short"));
  std::ofstream(path) << "  " << kToken << "  \nsecond line\n";
  auto token = BearerToken::from_file(path);
  ASSERT_TRUE(token.ok()) << token.error();
  EXPECT_TRUE(token->accepts(std::string("Bearer ") + kToken));
  std::remove(path.c_str());
}

constexpr const char* kViewToken = "a-viewer-token-of-some-length";
constexpr const char* kAdminToken = "an-admin-token-of-some-length";

/// A 0600 file of `text`, removed at the end of the test.
class TokenFile {
 public:
  explicit TokenFile(const std::string& text)
      : path_("/tmp/dh3-web-tokens-" + std::to_string(::getpid())) {
    std::ofstream(path_) << text;
    ::chmod(path_.c_str(), 0600);
  }
  ~TokenFile() { std::remove(path_.c_str()); }
  TokenFile(const TokenFile&) = delete;
  TokenFile& operator=(const TokenFile&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
};

TEST(BearerToken, ReadsATokenForEachRole) {
  const TokenFile file(std::string("# dh3-web tokens\n\nview ") + kViewToken + "\noperator  " +
                       kToken + "\nadmin\t" + kAdminToken + "\n");
  const auto tokens = BearerToken::from_file(file.path());
  ASSERT_TRUE(tokens.ok()) << tokens.error();
  const auto bearer = [](const char* token) { return std::string("Bearer ") + token; };
  EXPECT_EQ(tokens->role_of(bearer(kViewToken)), TokenRole::view);
  EXPECT_EQ(tokens->role_of(bearer(kToken)), TokenRole::operate);
  EXPECT_EQ(tokens->role_of(bearer(kAdminToken)), TokenRole::administer);
  EXPECT_EQ(tokens->role_of("Bearer view"), std::nullopt);
  EXPECT_EQ(tokens->role_of(bearer("a-viewer-token-of-some-lengtX")), std::nullopt);
  EXPECT_TRUE(tokens->grants(TokenRole::administer));

  const TokenFile operators(std::string("operator ") + kToken + "\n");
  const auto no_admin = BearerToken::from_file(operators.path());
  ASSERT_TRUE(no_admin.ok()) << no_admin.error();
  EXPECT_TRUE(no_admin->grants(TokenRole::operate));
  EXPECT_FALSE(no_admin->grants(TokenRole::administer));
  // A file of one token, as dh3-web always read it: an operator's.
  EXPECT_EQ(BearerToken::from_text(kToken).role_of(bearer(kToken)), TokenRole::operate);
}

TEST(BearerToken, RefusesARoleFileWithABadLine) {
  const auto refusal = [](const std::string& text) {
    const TokenFile file(text);
    auto tokens = BearerToken::from_file(file.path());
    return tokens.ok() ? std::string() : tokens.error();
  };
  EXPECT_THAT(refusal(std::string("root ") + kToken + "\n"),
              HasSubstr("line 1 of /tmp/dh3-web-tokens-"));
  EXPECT_THAT(refusal(std::string("root ") + kToken + "\n"),
              HasSubstr("is not \"ROLE TOKEN\" with ROLE view, operator or admin"));
  EXPECT_THAT(refusal(std::string("view ") + kViewToken + "\n" + kToken + "\n"),
              HasSubstr("line 2"));
  EXPECT_THAT(refusal(std::string("view ") + kViewToken + "\nadmin short\n"),
              HasSubstr("on line 2 of /tmp/dh3-web-tokens-"));
  EXPECT_THAT(refusal(std::string("view ") + kViewToken + "\nadmin short\n"),
              HasSubstr("too short"));
  EXPECT_THAT(refusal(std::string("view ") + kToken + "\nadmin " + kToken + "\n"),
              HasSubstr("given twice"));
  EXPECT_THAT(refusal("# only a comment\n"), HasSubstr("empty"));
}

TEST(BearerToken, RefusesAFileOthersOrItsGroupMayReadOrChange) {
  const std::string path = "/tmp/dh3-web-token-mode-" + std::to_string(::getpid());
  std::ofstream(path) << kToken << "\n";
  const auto refusal_at = [&](mode_t mode) {
    ::chmod(path.c_str(), mode);
    auto token = BearerToken::from_file(path);
    return token.ok() ? std::string() : token.error();
  };
  const std::string world = refusal_at(0644);
  EXPECT_THAT(world, HasSubstr("the token file " + path + " has mode 0644"));
  EXPECT_THAT(world, HasSubstr("other users may read or change the token"));
  EXPECT_THAT(world, HasSubstr("chmod 600 " + path));
  EXPECT_THAT(refusal_at(0602), HasSubstr("mode 0602: other users"));
  EXPECT_THAT(refusal_at(0660), HasSubstr("mode 0660: its group may read or change"));
  EXPECT_THAT(refusal_at(0600), IsEmpty());
  EXPECT_THAT(refusal_at(0400), IsEmpty());
  // Group reading only is the packaged layout (0640 root:dh3-web), and only
  // when root owns the file: another owner's group is nobody's decision.
  const std::string group_reads = refusal_at(0640);
  if (::geteuid() == 0) {
    EXPECT_THAT(group_reads, IsEmpty());
    ASSERT_EQ(::chown(path.c_str(), 65534, static_cast<gid_t>(-1)), 0);  // nobody's file
    EXPECT_THAT(refusal_at(0640), HasSubstr("mode 0640: its group"));
  } else {
    EXPECT_THAT(group_reads, HasSubstr("mode 0640: its group"));
  }
  std::remove(path.c_str());
}

TEST(AllowedHosts, OnLoopbackServesItsAddressAndTheLocalNamesOnly) {
  const AllowedHosts hosts("127.0.0.1", {});
  for (const char* host : {"127.0.0.1:8080", "localhost:8080", "LocalHost", "localhost.:8080",
                           "[::1]:8080", "127.0.0.1", ""}) {
    EXPECT_TRUE(hosts.allows(host)) << host;
  }
  // A rebinding page's own name, however it resolves, and other addresses.
  for (const char* host : {"attacker.example:8080", "attacker.example", "127.0.0.1.nip.io:8080",
                           "10.0.0.5:8080", "localhost.attacker.example", "[::2]:8080"}) {
    EXPECT_FALSE(hosts.allows(host)) << host;
  }
}

TEST(AllowedHosts, BeyondLoopbackServesTheListenAddressAndTheNamesGiven) {
  const AllowedHosts hosts("10.0.0.5", {"cell-pc.example", "Proxy.Example:443"});
  EXPECT_TRUE(hosts.allows("10.0.0.5:8080"));
  EXPECT_TRUE(hosts.allows("CELL-PC.example:8080"));
  EXPECT_TRUE(hosts.allows("proxy.example"));
  EXPECT_FALSE(hosts.allows("localhost:8080"));
  EXPECT_FALSE(hosts.allows("10.0.0.6:8080"));
  EXPECT_FALSE(hosts.allows("attacker.example"));
}

TEST(AllowedHosts, OnEveryInterfaceServesAnyAddressButNoOtherName) {
  const AllowedHosts hosts("0.0.0.0", {"cell-pc.example"});
  EXPECT_TRUE(hosts.allows("10.0.0.6:8080"));  // an address cannot be rebound to another site
  EXPECT_TRUE(hosts.allows("[fe80::1]:8080"));
  EXPECT_TRUE(hosts.allows("localhost"));
  EXPECT_TRUE(hosts.allows("cell-pc.example"));
  EXPECT_FALSE(hosts.allows("attacker.example:8080"));
  EXPECT_TRUE(AllowedHosts("::", {}).allows("192.168.1.2"));
}

TEST(WebOptions, WarnsWhenItListensBeyondLoopback) {
  WebOptions options;
  EXPECT_THAT(exposure_warning(options), IsEmpty());  // 127.0.0.1
  options.listen.host = "0.0.0.0";
  EXPECT_THAT(exposure_warning(options),
              AllOf(HasSubstr("dh3-web listens on 0.0.0.0 without --token-file"),
                    HasSubstr("anyone on that network can watch every hand")));
  options.listen.host = "::1";
  EXPECT_THAT(exposure_warning(options), IsEmpty());
  options.listen.host = "10.0.0.5";
  options.token_file = "/etc/dh3/web.token";
  EXPECT_THAT(exposure_warning(options),
              AllOf(HasSubstr("dh3-web listens on 10.0.0.5 over plain HTTP"),
                    HasSubstr("the bearer token crosses that network in clear text"),
                    HasSubstr("anyone there can watch every hand without it")));
  options.view_needs_token = true;
  EXPECT_THAT(exposure_warning(options), Not(HasSubstr("watch every hand")));
  options.listen.host = "127.0.0.1";
  EXPECT_THAT(exposure_warning(options), IsEmpty());
}

TEST(WebOptions, TakesFurtherHostNames) {
  const char* argv[] = {"dh3-web", "--allow-host", "cell-pc.example", "--allow-host", "proxy"};
  WebOptions options;
  std::ostringstream out;
  std::ostringstream err;
  EXPECT_EQ(parse_web_options(5, argv, options, out, err), std::nullopt) << err.str();
  EXPECT_THAT(options.allowed_hosts, ElementsAre("cell-pc.example", "proxy"));
}

TEST(WebOptions, KeepWorkersBesideTheStreams) {
  WebOptions defaults;
  std::ostringstream out;
  std::ostringstream err;
  const char* none[] = {"dh3-web"};
  ASSERT_EQ(parse_web_options(1, none, defaults, out, err), std::nullopt) << err.str();
  EXPECT_GE(defaults.max_streams, 64);
  EXPECT_GE(defaults.threads - defaults.max_streams, kWorkersBesideStreams);
  EXPECT_THAT(defaults.client.participant_name, HasSubstr("dh3-web"));

  WebOptions crowded;
  const char* argv[] = {"dh3-web", "--threads", "70", "--max-streams", "64"};
  EXPECT_EQ(parse_web_options(5, argv, crowded, out, err), 2);
  EXPECT_THAT(err.str(), HasSubstr("--threads 70 leaves too few workers beside --max-streams 64"));
  WebOptions raised;
  const char* more[] = {"dh3-web", "--threads", "140", "--max-streams", "128"};
  EXPECT_EQ(parse_web_options(5, more, raised, out, err), std::nullopt);
  EXPECT_EQ(raised.max_streams, 128);
}

TEST(WebOptions, ParsesListenAddresses) {
  EXPECT_EQ(parse_listen("0.0.0.0:80")->host, "0.0.0.0");
  EXPECT_EQ(parse_listen("0.0.0.0:80")->port, 80);
  EXPECT_EQ(parse_listen(":9000")->host, "127.0.0.1");
  EXPECT_EQ(parse_listen("[::1]:9000")->host, "::1");
  EXPECT_FALSE(parse_listen("localhost").ok());
  EXPECT_FALSE(parse_listen("127.0.0.1:").ok());
  EXPECT_FALSE(parse_listen("127.0.0.1:65536").ok());
  EXPECT_FALSE(parse_listen("127.0.0.1:80x").ok());
}

/// HandApi over a client on a domain with no service: every refusal is
/// dh3-web's own, and nothing is ever written.
class HandApiTest : public ::testing::Test {
 protected:
  static ClientOptions options() {
    ClientOptions o;
    o.domain = test::test_domain();
    return o;
  }
  HandApi api(bool with_token, bool view_needs_token = false) {
    if (!with_token) return api_with(std::nullopt, view_needs_token);
    return api_with(BearerToken::from_text(kToken), view_needs_token);
  }
  HandApi api_with(std::optional<BearerToken> tokens, bool view_needs_token = false) {
    AccessPolicy access;
    access.token = std::move(tokens);
    access.view_needs_token = view_needs_token;
    return HandApi(client_, access, std::chrono::seconds(1), "{\"openapi\":\"3.0.3\"}",
                   "dh3-web-1@cell-pc");
  }
  static ApiRequest post(std::string path, std::string body, bool token = true) {
    return ApiRequest{"POST", std::move(path), token ? std::string("Bearer ") + kToken : "",
                      std::move(body)};
  }
  void TearDown() override { EXPECT_EQ(client_.command_traffic().requests_written, 0U); }

  Client client_{options()};
};

TEST_F(HandApiTest, CommandsNeedTheToken) {
  auto a = api(true);
  ApiResponse none = a.handle(post("/api/hands/cell/bus0/1/init", "", false));
  EXPECT_EQ(none.status, 401);
  EXPECT_TRUE(none.ask_for_token);
  EXPECT_THAT(none.body, HasSubstr(R"("code":"UNAUTHORIZED")"));
  ApiRequest wrong = post("/api/hands/cell/bus0/1/init", "");
  wrong.authorization = "Bearer guessed-token-of-some-length";
  EXPECT_EQ(a.handle(wrong).status, 401);
  // Refused before the body is read: a caller without the token learns nothing.
  EXPECT_EQ(a.handle(post("/api/hands/cell/bus0/1/jump", "{", false)).status, 401);

  auto viewing_only = api(false);
  ApiResponse disabled = viewing_only.handle(post("/api/hands/cell/bus0/1/init", ""));
  EXPECT_EQ(disabled.status, 403);
  EXPECT_THAT(disabled.body, HasSubstr("COMMANDS_DISABLED"));
}

TEST_F(HandApiTest, RefusesBadPathsMethodsAndHands) {
  auto a = api(true);
  ApiResponse method = a.handle(ApiRequest{"DELETE", "/api/hands", "", ""});
  EXPECT_EQ(method.status, 405);
  EXPECT_EQ(method.allow, "GET");
  EXPECT_EQ(a.handle(ApiRequest{"GET", "/api/hands/cell/bus0/1/init", "", ""}).allow, "POST");
  EXPECT_EQ(a.handle(ApiRequest{"POST", "/api/stream", "", ""}).status, 405);
  EXPECT_EQ(a.handle(ApiRequest{"POST", "/api/openapi.json", "", ""}).status, 405);
  EXPECT_EQ(a.handle(ApiRequest{"GET", "/api/nothing", "", ""}).status, 404);
  EXPECT_EQ(a.handle(ApiRequest{"GET", "/api/hands/cell/bus0", "", ""}).status, 404);
  for (const char* id : {"x", "0", "256", "1a", "-1", ""}) {
    ApiResponse bad = a.handle(post(std::string("/api/hands/cell/bus0/") + id + "/init", ""));
    EXPECT_EQ(bad.status, 400) << id;
    EXPECT_THAT(bad.body, HasSubstr("is not a CAN ID (1-255)")) << id;
  }
  ApiResponse unknown = a.handle(ApiRequest{"GET", "/api/hands/cell/bus0/9", "", ""});
  EXPECT_EQ(unknown.status, 404);
  EXPECT_THAT(unknown.body, HasSubstr(R"("code":"UNKNOWN_HAND")"));
  EXPECT_EQ(a.handle(post("/api/hands/cell/bus0/9/move", R"({"position": 30})")).status, 404);
  // A bad body is refused before the hand is looked up.
  EXPECT_EQ(a.handle(post("/api/hands/cell/bus0/9/move", R"({"position": "x"})")).status, 400);
}

TEST_F(HandApiTest, ViewingCanNeedTheTokenToo) {
  auto open = api(true);
  EXPECT_EQ(open.handle(ApiRequest{"GET", "/api/hands", "", ""}).status, 200);
  EXPECT_FALSE(open.authorize_view("").has_value());
  auto closed = api(true, true);
  EXPECT_EQ(closed.handle(ApiRequest{"GET", "/api/hands", "", ""}).status, 401);
  EXPECT_EQ(closed.handle(ApiRequest{"GET", "/api/health", "", ""}).status, 401);
  EXPECT_TRUE(closed.authorize_view("").has_value());
  ApiResponse listed =
      closed.handle(ApiRequest{"GET", "/api/hands", std::string("Bearer ") + kToken, ""});
  EXPECT_EQ(listed.status, 200);
  EXPECT_EQ(listed.body, R"({"services":[],"hands":[]})");
  EXPECT_FALSE(closed.authorize_view(std::string("Bearer ") + kToken).has_value());
}

TEST_F(HandApiTest, SaysAtOnceWhetherATokenIsTheRightOne) {
  auto a = api(true);
  ApiResponse right =
      a.handle(ApiRequest{"GET", "/api/token", std::string("Bearer ") + kToken, ""});
  EXPECT_EQ(right.status, 200);
  expect_described_as("Token", Json::parse(right.body));
  EXPECT_THAT(right.body, HasSubstr(R"("console":"dh3-web-1@cell-pc")"));
  ApiResponse wrong =
      a.handle(ApiRequest{"GET", "/api/token", "Bearer guessed-token-of-some-length", ""});
  EXPECT_EQ(wrong.status, 401);
  EXPECT_THAT(wrong.body, HasSubstr("the bearer token is not the right one"));
  EXPECT_EQ(a.handle(ApiRequest{"GET", "/api/token", "", ""}).status, 401);
  EXPECT_EQ(a.handle(ApiRequest{"POST", "/api/token", "", ""}).status, 405);
  EXPECT_EQ(api(false).handle(ApiRequest{"GET", "/api/token", "Bearer x", ""}).status, 403);
}

TEST_F(HandApiTest, EachTokenMayDoWhatItsRoleMay) {
  const TokenFile file(std::string("view ") + kViewToken + "\noperator " + kToken + "\nadmin " +
                       kAdminToken + "\n");
  auto tokens = BearerToken::from_file(file.path());
  ASSERT_TRUE(tokens.ok()) << tokens.error();
  auto a = api_with(std::move(tokens).value(), /*view_needs_token=*/true);
  const auto as = [](ApiRequest request, const char* token) {
    request.authorization = std::string("Bearer ") + token;
    return request;
  };
  const ApiRequest init = post("/api/hands/cell/bus0/9/init", "");
  const ApiRequest set_id =
      post("/api/hands/cell/bus0/9/set-can-id", R"({"can_id": 2, "confirm": true})");
  const ApiRequest list{"GET", "/api/hands", "", ""};

  // Viewing: every role.
  for (const char* token : {kViewToken, kToken, kAdminToken}) {
    EXPECT_EQ(a.handle(as(list, token)).status, 200) << token;
  }
  // A viewer's token commands nothing.
  const ApiResponse viewer = a.handle(as(init, kViewToken));
  EXPECT_EQ(viewer.status, 403);
  EXPECT_THAT(viewer.body, HasSubstr("READ_ONLY_TOKEN"));
  EXPECT_EQ(a.handle(as(set_id, kViewToken)).status, 403);
  // An operator's commands, but no administrative command.
  EXPECT_EQ(a.handle(as(init, kToken)).status, 404);  // past the token: no such hand
  const ApiResponse operator_admin = a.handle(as(set_id, kToken));
  EXPECT_EQ(operator_admin.status, 403);
  EXPECT_THAT(operator_admin.body, HasSubstr("ADMIN_TOKEN_NEEDED"));
  // An admin's gets past the token to the hand (none here: 404, nothing sent).
  EXPECT_EQ(a.handle(as(set_id, kAdminToken)).status, 404);

  // /api/token says which role a token has.
  for (const auto& [token, role] : {std::pair{kViewToken, "view"}, std::pair{kToken, "operator"},
                                    std::pair{kAdminToken, "admin"}}) {
    const ApiResponse checked = a.handle(as(ApiRequest{"GET", "/api/token", "", ""}, token));
    EXPECT_EQ(checked.status, 200);
    EXPECT_THAT(checked.body, HasSubstr(std::string(R"("role":")") + role + "\""));
    expect_described_as("Token", Json::parse(checked.body));
  }
  // A file of viewers' tokens only enables no commands.
  auto viewers = api_with(BearerToken::from_text(kViewToken, TokenRole::view));
  EXPECT_THAT(viewers.handle(ApiRequest{"GET", "/api/health", "", ""}).body,
              HasSubstr(R"("commands_enabled":false)"));
  EXPECT_THAT(a.handle(as(ApiRequest{"GET", "/api/health", "", ""}, kViewToken)).body,
              HasSubstr(R"("commands_enabled":true)"));
}

TEST_F(HandApiTest, StreamsAreCountedAndTheOnePastTheLimitRefused) {
  EventStreamOptions limited;
  limited.max_readers = 2;
  EventStream stream(client_, limited);
  auto first = stream.open();
  auto second = stream.open();
  ASSERT_NE(first, nullptr);
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(stream.open(), nullptr);
  first.reset();  // a page closed: its place is free again
  auto third = stream.open();
  ASSERT_NE(third, nullptr);
  // The snapshot ends with ready; with nothing new the heartbeat follows.
  EXPECT_THAT(third->next(std::chrono::seconds(5)).value_or(""), HasSubstr("event: ready"));
  EXPECT_EQ(third->next(std::chrono::milliseconds(1)), "");
  EXPECT_EQ(stream.heartbeat(), ": keep-alive\n\n");
  stream.close();
  EXPECT_EQ(third->next(std::chrono::milliseconds(1)), std::nullopt);
}

TEST_F(HandApiTest, HealthAndTheHandListAreDescribed) {
  auto a = api(true);
  expect_described_as("Health",
                      Json::parse(a.handle(ApiRequest{"GET", "/api/health", "", ""}).body));
  expect_described_as("Hands", Json::parse(a.handle(ApiRequest{"GET", "/api/hands", "", ""}).body));
}

TEST_F(HandApiTest, AlarmsAreListedAndAcknowledgingOneIsACommand) {
  CellAlarms alarms(client_);
  EventStream stream(client_);
  alarms.set_listener([&stream](std::uint64_t version, const std::string& json) {
    stream.publish_alarms(version, json);
  });
  AccessPolicy access;
  access.token = BearerToken::from_text(kToken);
  HandApi a(client_, access, std::chrono::seconds(1), "{}", "dh3-web-1@cell-pc", &alarms);
  alarms.record_failure("cell/bus0/3", "move", 409, "NOT_INITIALIZED", "initialize it first");

  ApiResponse listed = a.handle(ApiRequest{"GET", "/api/alarms", "", ""});
  ASSERT_EQ(listed.status, 200);
  const auto list = Json::parse(listed.body);
  expect_described_as("Alarms", list);
  ASSERT_EQ(list["alarms"].size(), 1U);
  const auto alarm = list["alarms"][0];
  EXPECT_EQ(alarm["key"], "command:1");
  EXPECT_EQ(alarm["text"],
            "Command to hand cell/bus0/3 failed: Error in move (HTTP 409 NOT_INITIALIZED): "
            "initialize it first");
  EXPECT_EQ(alarm["acknowledged"], false);
  const std::string path =
      "/api/alarms/" + std::to_string(alarm["id"].get<std::uint64_t>()) + "/acknowledge";

  EXPECT_EQ(a.handle(post(path, "", false)).status, 401);
  EXPECT_EQ(a.handle(ApiRequest{"GET", path, "", ""}).status, 405);
  EXPECT_EQ(a.handle(ApiRequest{"POST", "/api/alarms", "", ""}).status, 405);
  ApiResponse unknown = a.handle(post("/api/alarms/999/acknowledge", ""));
  EXPECT_EQ(unknown.status, 404);
  EXPECT_THAT(unknown.body, HasSubstr("UNKNOWN_ALARM"));
  EXPECT_EQ(a.handle(post("/api/alarms/x/acknowledge", "")).status, 404);
  EXPECT_FALSE(Json::parse(a.handle(ApiRequest{"GET", "/api/alarms", "", ""}).body)["alarms"][0]
                   ["acknowledged"]);

  ApiResponse acknowledged = a.handle(post(path, ""));
  ASSERT_EQ(acknowledged.status, 200) << acknowledged.body;
  expect_described_as("Alarm", Json::parse(acknowledged.body));
  EXPECT_TRUE(Json::parse(acknowledged.body)["acknowledged"]);
  // Every client of this console sees it acknowledged: the API and a new stream.
  EXPECT_TRUE(Json::parse(a.handle(ApiRequest{"GET", "/api/alarms", "", ""}).body)["alarms"][0]
                  ["acknowledged"]);
  auto reader = stream.open();
  ASSERT_NE(reader, nullptr);
  const std::string snapshot = reader->next(std::chrono::seconds(5)).value_or("");
  EXPECT_THAT(snapshot, HasSubstr("event: alarms"));
  EXPECT_THAT(snapshot, HasSubstr(R"("key":"command:1")"));
  EXPECT_THAT(snapshot, HasSubstr(R"("acknowledged":true)"));
  // A change goes to the open stream at once.
  alarms.record_failure("cell/bus0/1", "stop", 503, "BUS_DOWN", "the bus is down");
  const std::string change = reader->next(std::chrono::seconds(5)).value_or("");
  EXPECT_THAT(change, HasSubstr("event: alarms"));
  EXPECT_THAT(change, HasSubstr(R"("key":"command:2")"));
  alarms.set_listener(nullptr);
}

TEST(HttpStatus, SaysWhatAReplysCodeMeans) {
  EXPECT_EQ(http_status(Code::ok), 200);
  EXPECT_EQ(http_status(Code::invalid_argument), 400);
  EXPECT_EQ(http_status(Code::unknown_hand), 404);
  EXPECT_EQ(http_status(Code::not_initialized), 409);
  EXPECT_EQ(http_status(Code::bus_down), 503);
  EXPECT_EQ(http_status(Code::no_reply), 504);
}

}  // namespace
}  // namespace dh3::web
