// Every profile a program asks for (profiles.hpp: requested_profiles()) resolves in every shipped profile set: the
// QoS file config/dds/canyon_profiles.xml alone, with each deployment file deploy/dds/*.xml on top, and with each
// secure variant deploy/security/make-pki.sh makes of them on top. Each set is loaded into a fresh profile store, its
// participant is created from the profile the programs use with it (proving its transports and security properties
// are usable), and every writer and reader profile is looked up through the participant's publisher and subscriber.
// The check itself must be able to fail: a QoS file without a profile, a deployment file without its participant,
// and a deployment file that repeats a QoS profile are each caught.

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/dds/dds.hpp"
#include "canyon/dds/profiles.hpp"

namespace canyon::dds {
namespace {

namespace fs = std::filesystem;
using eprosima::fastrtps::types::ReturnCode_t;

const fs::path kSource = CANYON_SOURCE_DIR;
const fs::path kQosFile = kSource / "config/dds/canyon_profiles.xml";

int test_domain() {
  return 20 + static_cast<int>((::getpid() + 11) % 80);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

/// The requested profiles that do not resolve with `qos_file` and `deployment` on top (a fresh profile store), or the
/// loading error.
std::vector<std::string> unresolved(const fs::path& qos_file, const fs::path& deployment) {
  eprosima::fastrtps::xmlparser::XMLProfileManager::DeleteInstance();
  auto set = load_profile_files(qos_file.string(), deployment.string());
  if (!set) return {"cannot load: " + set.error().to_string()};
  std::vector<std::string> missing;
  const bool with_deployment = !set->deployment_file.empty();
  fdds::DomainParticipantQos participant_qos;
  for (const RequestedProfile& r : requested_profiles()) {
    if (r.kind == ProfileKind::Participant && r.deployment == with_deployment &&
        fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(r.name, participant_qos) !=
            ReturnCode_t::RETCODE_OK) {
      missing.push_back(std::string("participant ") + r.name);
    }
  }
  auto participant = DdsParticipant::create(test_domain(), set->participant_profile());
  if (!participant) {
    missing.push_back("participant not created: " + participant.error().to_string());
    return missing;
  }
  fdds::Publisher* publisher = (*participant)->get()->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  fdds::Subscriber* subscriber = (*participant)->get()->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  fdds::DataWriterQos writer_qos;
  fdds::DataReaderQos reader_qos;
  for (const RequestedProfile& r : requested_profiles()) {
    if (r.kind == ProfileKind::DataWriter &&
        publisher->get_datawriter_qos_from_profile(r.name, writer_qos) != ReturnCode_t::RETCODE_OK) {
      missing.push_back(std::string("data_writer ") + r.name + " (" + r.used_by + ")");
    }
    if (r.kind == ProfileKind::DataReader &&
        subscriber->get_datareader_qos_from_profile(r.name, reader_qos) != ReturnCode_t::RETCODE_OK) {
      missing.push_back(std::string("data_reader ") + r.name + " (" + r.used_by + ")");
    }
  }
  participant->reset();  // deletes the publisher and subscriber with it
  return missing;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += "\n  " + x;
  return s;
}

std::vector<fs::path> deployment_files() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kSource / "deploy/dds")) {
    if (entry.path().extension() == ".xml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

class ProfileSets : public ::testing::Test {
 protected:
  void TearDown() override {
    eprosima::fastrtps::xmlparser::XMLProfileManager::DeleteInstance();
    (void)load_profiles("");  // the store as the other tests of this process expect it
  }
  fs::path temp_dir() {
    fs::path dir = fs::temp_directory_path() / ("canyon_profile_sets_" + std::to_string(::getpid()) + "_" +
                                                ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    dirs_.push_back(dir);
    return dir;
  }
  ~ProfileSets() override {
    for (const fs::path& d : dirs_) fs::remove_all(d);
  }
  std::vector<fs::path> dirs_;
};

TEST_F(ProfileSets, EveryRequestedProfileIsListedOnce) {
  std::set<std::string> names;
  for (const RequestedProfile& r : requested_profiles()) EXPECT_TRUE(names.insert(r.name).second) << r.name;
  EXPECT_EQ(names.count(profile::kParticipant), 1U);
  EXPECT_EQ(names.count(profile::kDeploymentParticipant), 1U);
}

TEST_F(ProfileSets, ShippedQosFileAlone) {
  const auto missing = unresolved(kQosFile, "");
  EXPECT_TRUE(missing.empty()) << kQosFile << ":" << joined(missing);
}

TEST_F(ProfileSets, EachDeploymentFileOnTopOfTheQosFile) {
  const std::vector<fs::path> files = deployment_files();
  ASSERT_EQ(files.size(), 3U) << "lan, wan-discovery-server, wan-initial-peers";
  for (const fs::path& file : files) {
    const auto missing = unresolved(kQosFile, file);
    EXPECT_TRUE(missing.empty()) << file << ":" << joined(missing);
  }
}

TEST_F(ProfileSets, EachSecureVariantOnTopOfTheQosFile) {
  if (std::system("command -v openssl > /dev/null") != 0) GTEST_SKIP() << "openssl not found: no secure variants";
  const fs::path pki = temp_dir();
  const std::string make = "bash " + (kSource / "deploy/security/make-pki.sh").string() + " " + pki.string() + " > " +
                           (pki / "make-pki.log").string() + " 2>&1";
  ASSERT_EQ(std::system(make.c_str()), 0) << read_text(pki / "make-pki.log");
  int checked = 0;
  for (const char* role : {"base", "rover", "monitor"}) {
    for (const fs::path& plain : deployment_files()) {
      const fs::path secure = pki / role / plain.filename();
      ASSERT_TRUE(fs::exists(secure)) << secure;
      ASSERT_NE(read_text(secure).find("dds.sec.auth.plugin"), std::string::npos) << secure;
      const auto missing = unresolved(kQosFile, secure);
      EXPECT_TRUE(missing.empty()) << secure << ":" << joined(missing);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

TEST_F(ProfileSets, DeploymentFilesHoldOnlyTransportAndDiscovery) {
  const std::regex qos_element("<(data_writer|data_reader|topic|publisher|subscriber)[ >]");
  const std::regex participant("<participant profile_name=\"([^\"]*)\"");
  for (const fs::path& file : deployment_files()) {
    const std::string text = read_text(file);
    EXPECT_FALSE(std::regex_search(text, qos_element)) << file << " defines QoS: it belongs in " << kQosFile;
    std::vector<std::string> names;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), participant); it != std::sregex_iterator(); ++it) {
      names.push_back((*it)[1]);
    }
    EXPECT_EQ(names, std::vector<std::string>{profile::kDeploymentParticipant}) << file;
  }
}

// The checks above can fail: each broken file is caught, naming what is wrong.
TEST_F(ProfileSets, TheCheckCatchesAMissingQosProfile) {
  const fs::path dir = temp_dir();
  std::string qos = read_text(kQosFile);
  const std::regex vio_writer("<data_writer profile_name=\"vio_writer\">[\\s\\S]*?</data_writer>");
  ASSERT_TRUE(std::regex_search(qos, vio_writer));
  write_text(dir / "canyon_profiles.xml", std::regex_replace(qos, vio_writer, ""));
  for (const fs::path& deployment : {fs::path(), kSource / "deploy/dds/lan.xml"}) {
    const auto missing = unresolved(dir / "canyon_profiles.xml", deployment);
    ASSERT_EQ(missing.size(), 1U) << joined(missing);
    EXPECT_NE(missing[0].find("data_writer vio_writer"), std::string::npos) << missing[0];
  }
}

TEST_F(ProfileSets, TheCheckCatchesADeploymentFileWithoutItsParticipant) {
  const fs::path dir = temp_dir();
  const std::string lan = read_text(kSource / "deploy/dds/lan.xml");
  write_text(dir / "lan.xml", std::regex_replace(lan, std::regex("canyon_deployment"), "lan_participant"));
  const auto missing = unresolved(kQosFile, dir / "lan.xml");
  ASSERT_EQ(missing.size(), 1U) << joined(missing);
  EXPECT_NE(missing[0].find("must define the participant profile 'canyon_deployment'"), std::string::npos)
      << missing[0];
}

TEST_F(ProfileSets, TheCheckCatchesADeploymentFileThatRepeatsAQosProfile) {
  const fs::path dir = temp_dir();
  std::string lan = read_text(kSource / "deploy/dds/lan.xml");
  const std::string writer =
      "<data_writer profile_name=\"rtcm_writer\"><qos><reliability><kind>BEST_EFFORT</kind></reliability></qos>"
      "</data_writer>\n  </profiles>";
  lan.replace(lan.find("</profiles>"), std::string("</profiles>").size(), writer);
  write_text(dir / "lan.xml", lan);
  const auto missing = unresolved(kQosFile, dir / "lan.xml");
  ASSERT_EQ(missing.size(), 1U) << joined(missing);
  EXPECT_NE(missing[0].find("defined twice"), std::string::npos) << missing[0];
}

TEST_F(ProfileSets, TheShippedQosFileGivenAsDeploymentIsNoDeployment) {
  auto set = load_profile_files(kQosFile.string(), kQosFile.string());
  ASSERT_TRUE(set.ok()) << set.error().to_string();
  EXPECT_TRUE(set->deployment_file.empty());
  EXPECT_STREQ(set->participant_profile(), profile::kParticipant);
}

}  // namespace
}  // namespace canyon::dds
