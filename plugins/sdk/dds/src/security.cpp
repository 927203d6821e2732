#include "beaconloc/dds/security.hpp"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <tinyxml2.h>

#include <atomic>
#include <ctime>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutConsumer.hpp>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>

namespace beaconloc::dds {
namespace {

namespace fs = std::filesystem;

std::atomic<std::uint64_t> g_undecodable_secure{0};

// Fast DDS's crypto plugin logs a received message whose authentication tag does not match as a
// warning of category SECURITY_CRYPTO (AESGCMGMAC_Transform, 2.9.1). Counts those; prints errors
// as Fast DDS's default consumer (StdoutConsumer) did; drops the other warnings, which the default
// verbosity (errors only) did not report either.
class SecureMessageCounter : public eprosima::fastdds::dds::LogConsumer {
 public:
  void Consume(const eprosima::fastdds::dds::Log::Entry& entry) override {
    using eprosima::fastdds::dds::Log;
    const std::string category = entry.context.category ? entry.context.category : "";
    if (category == "SECURITY_CRYPTO" && entry.message == "Error decoding content") {
      ++g_undecodable_secure;
      return;
    }
    if (entry.kind == Log::Kind::Error) errors_.Consume(entry);
  }

 private:
  eprosima::fastdds::dds::StdoutConsumer errors_;
};

void install_secure_message_counter() {
  static std::once_flag once;
  std::call_once(once, [] {
    using eprosima::fastdds::dds::Log;
    Log::ClearConsumers();
    Log::RegisterConsumer(std::make_unique<SecureMessageCounter>());
    Log::SetVerbosity(Log::Kind::Warning);
  });
}

struct BioFree {
  void operator()(BIO* b) const { BIO_free(b); }
};
struct X509Free {
  void operator()(X509* x) const { X509_free(x); }
};
struct KeyFree {
  void operator()(EVP_PKEY* k) const { EVP_PKEY_free(k); }
};
struct StoreFree {
  void operator()(X509_STORE* s) const { X509_STORE_free(s); }
};
struct StoreCtxFree {
  void operator()(X509_STORE_CTX* c) const { X509_STORE_CTX_free(c); }
};
struct CrlFree {
  void operator()(X509_CRL* c) const { X509_CRL_free(c); }
};

std::unique_ptr<BIO, BioFree> open_pem(const std::string& path) {
  return std::unique_ptr<BIO, BioFree>(BIO_new_file(path.c_str(), "r"));
}

std::unique_ptr<X509, X509Free> read_certificate(const std::string& path, const std::string& what) {
  auto bio = open_pem(path);
  if (!bio) throw SecurityError(what + " '" + path + "' cannot be read");
  std::unique_ptr<X509, X509Free> cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  if (!cert) throw SecurityError(what + " '" + path + "' is not a PEM certificate");
  return cert;
}

std::string asn1_time_text(const ASN1_TIME* t) {
  std::unique_ptr<BIO, BioFree> bio(BIO_new(BIO_s_mem()));
  ASN1_TIME_print(bio.get(), t);
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

std::string file_uri(const std::string& path) { return "file://" + path; }

struct Pkcs7Free {
  void operator()(PKCS7* p) const { PKCS7_free(p); }
};

std::string openssl_reason() {
  const char* reason = ERR_reason_error_string(ERR_get_error());
  return reason ? reason : "unknown";
}

// The document an S/MIME file signed by the CA holds, verified as Fast DDS verifies it
// (Permissions.cpp: PKCS7_verify with PKCS7_TEXT).
std::string signed_document(const std::string& path, X509* ca, const std::string& ca_path,
                            const std::string& what) {
  auto in = open_pem(path);
  if (!in) throw SecurityError(what + " '" + path + "' cannot be read");
  BIO* content = nullptr;
  std::unique_ptr<PKCS7, Pkcs7Free> p7(SMIME_read_PKCS7(in.get(), &content));
  std::unique_ptr<BIO, BioFree> content_owner(content);
  if (!p7) throw SecurityError(what + " '" + path + "' is not an S/MIME signed document");
  std::unique_ptr<X509_STORE, StoreFree> store(X509_STORE_new());
  X509_STORE_add_cert(store.get(), ca);
  std::unique_ptr<BIO, BioFree> out(BIO_new(BIO_s_mem()));
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content, out.get(), PKCS7_TEXT) != 1) {
    throw SecurityError(what + " '" + path + "' is not signed by the permissions CA " + ca_path + ": " +
                        openssl_reason());
  }
  char* data = nullptr;
  const long n = BIO_get_mem_data(out.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

std::string subject_rfc2253(X509* cert) {
  std::unique_ptr<BIO, BioFree> bio(BIO_new(BIO_s_mem()));
  X509_NAME_print_ex(bio.get(), X509_get_subject_name(cert), 0, XN_FLAG_RFC2253);
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

std::string trimmed(const char* text) {
  const std::string s = text ? text : "";
  const auto first = s.find_first_not_of(" \t\r\n");
  const auto last = s.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? "" : s.substr(first, last - first + 1);
}

// A grant's time (xs:dateTime, "2026-12-05T12:00:00") in seconds since the epoch, read as UTC (Fast
// DDS 2.9 reads it as local time: scripts/deployment-keys.sh starts a grant a day back); nullopt when
// it is not one.
std::optional<std::int64_t> grant_time(const std::string& text) {
  std::tm t{};
  if (!::strptime(text.c_str(), "%Y-%m-%dT%H:%M:%S", &t)) return std::nullopt;
  return static_cast<std::int64_t>(::timegm(&t));
}

// The permissions document's grant for this identity is there and valid at now_unix_s.
void check_grant(const std::string& document, const std::string& path, const std::string& subject,
                 std::int64_t now_unix_s) {
  tinyxml2::XMLDocument xml;
  if (xml.Parse(document.c_str(), document.size()) != tinyxml2::XML_SUCCESS) {
    throw SecurityError("permissions '" + path + "' are not XML: " + std::string(xml.ErrorStr()));
  }
  const tinyxml2::XMLElement* dds = xml.FirstChildElement("dds");
  const tinyxml2::XMLElement* permissions = dds ? dds->FirstChildElement("permissions") : nullptr;
  std::string named;
  for (const tinyxml2::XMLElement* grant = permissions ? permissions->FirstChildElement("grant") : nullptr;
       grant; grant = grant->NextSiblingElement("grant")) {
    const tinyxml2::XMLElement* name = grant->FirstChildElement("subject_name");
    const std::string grant_subject = trimmed(name ? name->GetText() : nullptr);
    if (grant_subject != subject) {
      named += (named.empty() ? "" : ", ") + grant_subject;
      continue;
    }
    const tinyxml2::XMLElement* validity = grant->FirstChildElement("validity");
    const tinyxml2::XMLElement* from = validity ? validity->FirstChildElement("not_before") : nullptr;
    const tinyxml2::XMLElement* to = validity ? validity->FirstChildElement("not_after") : nullptr;
    const std::string from_text = trimmed(from ? from->GetText() : nullptr);
    const std::string to_text = trimmed(to ? to->GetText() : nullptr);
    const auto from_s = grant_time(from_text);
    const auto to_s = grant_time(to_text);
    if (!from_s || !to_s) {
      throw SecurityError("permissions '" + path + "': the grant of " + subject + " has no validity");
    }
    if (now_unix_s > *to_s) {
      throw SecurityError("permissions '" + path + "': the grant of " + subject + " expired on " + to_text +
                          " (issue them again: scripts/deployment-keys.sh enclave)");
    }
    if (now_unix_s < *from_s) {
      throw SecurityError("permissions '" + path + "': the grant of " + subject + " is not valid before " +
                          from_text);
    }
    return;
  }
  throw SecurityError("permissions '" + path + "' grant nothing to this identity (" + subject +
                      "); they name " + (named.empty() ? std::string("no subject") : named));
}

}  // namespace

std::string default_enclave(const std::string& participant_name) {
  const std::string gateway = "beaconloc.gateway.", bridge = "beaconloc.bridge.",
                    localizer = "beaconloc.localizer";
  if (participant_name.rfind(gateway, 0) == 0)
    return "/beaconloc/gateway/" + participant_name.substr(gateway.size());
  if (participant_name.rfind(bridge, 0) == 0)
    return "/beaconloc/bridge/" + participant_name.substr(bridge.size());
  if (participant_name == "beaconloc.decoder") return "/beaconloc/decoder";
  if (participant_name.rfind(localizer, 0) == 0) return "/beaconloc/localizer";
  return "/beaconloc/monitor";
}

EnclaveFiles check_enclave(const SecurityOptions& options, const std::string& enclave,
                           std::int64_t now_unix_s) {
  std::error_code error;
  const fs::path keystore = fs::absolute(options.keystore, error);
  if (error || !fs::is_directory(keystore)) {
    throw SecurityError("keystore '" + options.keystore +
                        "' is not a directory (make one with "
                        "scripts/deployment-keys.sh deployment KEYSTORE ROBOTS)");
  }
  if (enclave.empty() || enclave.front() != '/' || enclave.find("..") != std::string::npos) {
    throw SecurityError("enclave '" + enclave + "' is not an absolute name such as /beaconloc/decoder");
  }
  const fs::path dir = keystore / "enclaves" / enclave.substr(1);
  if (!fs::is_directory(dir)) {
    throw SecurityError("keystore '" + options.keystore + "' has no enclave " + enclave +
                        " (make it with "
                        "scripts/deployment-keys.sh enclave KEYSTORE ROLE [ROBOT])");
  }
  EnclaveFiles files;
  const auto need = [&](const char* name) {
    const fs::path p = dir / name;
    if (!fs::is_regular_file(p) || !std::ifstream(p).good()) {
      throw SecurityError("enclave " + enclave + ": " + p.string() + " is missing or unreadable");
    }
    return p.string();
  };
  files.identity_ca = need("identity_ca.cert.pem");
  files.certificate = need("cert.pem");
  files.private_key = need("key.pem");
  files.permissions_ca = need("permissions_ca.cert.pem");
  files.governance = need("governance.p7s");
  files.permissions = need("permissions.p7s");
  // The enclave's copy of the revocation list (where rmw looks for it), else the keystore's.
  for (const fs::path& crl : {dir / "crl.pem", keystore / "public" / "crl.pem"}) {
    if (fs::is_regular_file(crl)) {
      files.crl = crl.string();
      break;
    }
  }

  auto cert = read_certificate(files.certificate, "enclave " + enclave + ": identity certificate");
  auto ca = read_certificate(files.identity_ca, "enclave " + enclave + ": identity CA");
  const std::time_t now = static_cast<std::time_t>(now_unix_s);
  if (X509_cmp_time(X509_get0_notAfter(cert.get()), const_cast<std::time_t*>(&now)) < 0) {
    throw SecurityError("enclave " + enclave + ": identity certificate " + files.certificate +
                        " expired on " + asn1_time_text(X509_get0_notAfter(cert.get())) +
                        " (issue a new one: scripts/deployment-keys.sh enclave)");
  }
  if (X509_cmp_time(X509_get0_notBefore(cert.get()), const_cast<std::time_t*>(&now)) > 0) {
    throw SecurityError("enclave " + enclave + ": identity certificate " + files.certificate +
                        " is not valid before " + asn1_time_text(X509_get0_notBefore(cert.get())));
  }
  std::unique_ptr<X509_STORE, StoreFree> store(X509_STORE_new());
  X509_STORE_add_cert(store.get(), ca.get());
  if (!files.crl.empty()) {
    auto bio = open_pem(files.crl);
    std::unique_ptr<X509_CRL, CrlFree> list(bio ? PEM_read_bio_X509_CRL(bio.get(), nullptr, nullptr, nullptr)
                                                : nullptr);
    if (!list) throw SecurityError("revocation list '" + files.crl + "' is not a PEM CRL");
    X509_STORE_add_crl(store.get(), list.get());
    X509_STORE_set_flags(store.get(), X509_V_FLAG_CRL_CHECK);
  }
  std::unique_ptr<X509_STORE_CTX, StoreCtxFree> context(X509_STORE_CTX_new());
  X509_STORE_CTX_init(context.get(), store.get(), cert.get(), nullptr);
  X509_STORE_CTX_set_time(context.get(), 0, now);
  if (X509_verify_cert(context.get()) != 1) {
    const int why = X509_STORE_CTX_get_error(context.get());
    throw SecurityError("enclave " + enclave + ": identity certificate " + files.certificate +
                        " is not accepted by the identity CA " + files.identity_ca + ": " +
                        X509_verify_cert_error_string(why));
  }
  auto key_bio = open_pem(files.private_key);
  std::unique_ptr<EVP_PKEY, KeyFree> key(
      key_bio ? PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!key)
    throw SecurityError("enclave " + enclave + ": " + files.private_key + " is not a PEM private key");
  if (X509_check_private_key(cert.get(), key.get()) != 1) {
    throw SecurityError("enclave " + enclave + ": " + files.private_key + " is not the key of " +
                        files.certificate);
  }
  auto permissions_ca = read_certificate(files.permissions_ca, "enclave " + enclave + ": permissions CA");
  signed_document(files.governance, permissions_ca.get(), files.permissions_ca,
                  "enclave " + enclave + ": governance");
  check_grant(signed_document(files.permissions, permissions_ca.get(), files.permissions_ca,
                              "enclave " + enclave + ": permissions"),
              files.permissions, subject_rfc2253(cert.get()), now_unix_s);
  return files;
}

void enable_security(const EnclaveFiles& files, eprosima::fastdds::dds::DomainParticipantQos& qos) {
  install_secure_message_counter();
  auto& p = qos.properties().properties();
  const auto set = [&](const std::string& name, const std::string& value) { p.emplace_back(name, value); };
  set("dds.sec.auth.plugin", "builtin.PKI-DH");
  set("dds.sec.auth.builtin.PKI-DH.identity_ca", file_uri(files.identity_ca));
  set("dds.sec.auth.builtin.PKI-DH.identity_certificate", file_uri(files.certificate));
  set("dds.sec.auth.builtin.PKI-DH.private_key", file_uri(files.private_key));
  if (!files.crl.empty()) set("dds.sec.auth.builtin.PKI-DH.identity_crl", file_uri(files.crl));
  set("dds.sec.access.plugin", "builtin.Access-Permissions");
  set("dds.sec.access.builtin.Access-Permissions.permissions_ca", file_uri(files.permissions_ca));
  set("dds.sec.access.builtin.Access-Permissions.governance", file_uri(files.governance));
  set("dds.sec.access.builtin.Access-Permissions.permissions", file_uri(files.permissions));
  set("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

std::uint64_t undecodable_secure_messages() { return g_undecodable_secure.load(); }

}  // namespace beaconloc::dds
