#!/usr/bin/env bash
# shellcheck disable=SC2034 # the rules_* variables are read through ${!rules} in make_domain
# DDS-Security material for canyon (Fast DDS builtin plugins: PKI-DH authentication, Access-Permissions, AES-GCM-GMAC):
# a test identity CA and permissions CA, one identity per role, the governance and permissions documents signed by
# the permissions CA, and secure variants of deploy/dds/*.xml for each role.
#
#   make-pki.sh OUT_DIR [--domains MIN-MAX]
#
# OUT_DIR/ca/             identity_ca.{pem,key}, permissions_ca.{pem,key}  (keep the keys off the hosts)
# OUT_DIR/governance.p7s  signed governance: unauthenticated participants refused, discovery and liveliness
#                         encrypted; topics canyon/* with read and write access control, submessages (metadata) and
#                         data encrypted and authenticated (AES-GCM), so a tampered packet is rejected
# OUT_DIR/ROLE/           cert.pem, key.pem, permissions.p7s, and lan.xml, wan-initial-peers.xml,
#                         wan-discovery-server.xml: the deployment files with this role's security properties in
#                         their participant profile canyon_deployment (transport, discovery and security only:
#                         like the plain ones they are loaded on top of config/dds/canyon_profiles.xml)
# Roles and permissions (topic names are fnmatch patterns; default DENY):
#   base     publish canyon/rtcm
#   rover    subscribe canyon/rtcm; publish canyon/* except canyon/rtcm (solutions, stage outputs, timing)
#   monitor  subscribe canyon/*; publish nothing
#   intruder an identity of ANOTHER CA (rogue/), with its own self-consistent governance and permissions: for tests
# Paths inside the profiles are absolute (OUT_DIR as given, made absolute). ECDSA P-256 keys, 10-year validity.
set -euo pipefail

usage() {
  echo "usage: $0 OUT_DIR [--domains MIN-MAX]" >&2
  exit 2
}
(($# >= 1)) || usage
out="$1"
shift
domains="0-232"
while (($# > 0)); do
  case "$1" in
    --domains)
      domains="${2:-}"
      shift 2 || usage
      ;;
    *) usage ;;
  esac
done
[[ "${domains}" =~ ^([0-9]+)-([0-9]+)$ ]] || usage
dmin="${BASH_REMATCH[1]}"
dmax="${BASH_REMATCH[2]}"
command -v openssl > /dev/null || {
  echo "make-pki: error: openssl not found" >&2
  exit 1
}
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
dds_dir="${here}/../dds"
mkdir -p "${out}"
out="$(cd "${out}" && pwd)"
days=3650

make_ca() { # DIR NAME CN
  openssl ecparam -name prime256v1 -genkey -noout -out "$1/$2.key" 2> /dev/null
  openssl req -new -x509 -sha256 -key "$1/$2.key" -out "$1/$2.pem" -days "${days}" \
    -subj "/C=DE/O=canyon/CN=$3" 2> /dev/null
}

make_identity() { # CA_DIR ROLE_DIR CN
  openssl ecparam -name prime256v1 -genkey -noout -out "$2/key.pem" 2> /dev/null
  openssl req -new -sha256 -key "$2/key.pem" -out "$2/req.csr" -subj "/C=DE/O=canyon/CN=$3" 2> /dev/null
  openssl x509 -req -sha256 -in "$2/req.csr" -CA "$1/identity_ca.pem" -CAkey "$1/identity_ca.key" \
    -CAcreateserial -out "$2/cert.pem" -days "${days}" 2> /dev/null
  rm -f "$2/req.csr"
}

sign() { # CA_DIR IN OUT
  openssl smime -sign -in "$2" -text -out "$3" -signer "$1/permissions_ca.pem" -inkey "$1/permissions_ca.key" \
    2> /dev/null
}

governance() {
  cat << GOV
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>${dmin}</min><max>${dmax}</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>canyon/*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
GOV
}

# permissions SUBJECT GRANT_NAME RULES_XML
permissions() {
  cat << PERM
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$2">
      <subject_name>$1</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2040-01-01T00:00:00</not_after></validity>
$3
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
PERM
}

dom="<domains><id_range><min>${dmin}</min><max>${dmax}</max></id_range></domains>"
rules_base="      <allow_rule>${dom}
        <publish><topics><topic>canyon/rtcm</topic></topics></publish>
      </allow_rule>"
rules_rover="      <deny_rule>${dom}
        <publish><topics><topic>canyon/rtcm</topic></topics></publish>
      </deny_rule>
      <allow_rule>${dom}
        <publish><topics><topic>canyon/*</topic></topics></publish>
        <subscribe><topics><topic>canyon/rtcm</topic></topics></subscribe>
      </allow_rule>"
rules_monitor="      <allow_rule>${dom}
        <subscribe><topics><topic>canyon/*</topic></topics></subscribe>
      </allow_rule>"
rules_intruder="      <allow_rule>${dom}
        <publish><topics><topic>canyon/*</topic></topics></publish>
        <subscribe><topics><topic>canyon/*</topic></topics></subscribe>
      </allow_rule>"

# Inserts the security properties of a role into the participant of a deploy profile (before its </rtps>).
secure_profile() { # SRC DST CA_DIR ROLE_DIR GOVERNANCE
  local props
  props="        <propertiesPolicy>
          <properties>
            <property><name>dds.sec.auth.plugin</name><value>builtin.PKI-DH</value></property>
            <property><name>dds.sec.auth.builtin.PKI-DH.identity_ca</name><value>file://$3/identity_ca.pem</value></property>
            <property><name>dds.sec.auth.builtin.PKI-DH.identity_certificate</name><value>file://$4/cert.pem</value></property>
            <property><name>dds.sec.auth.builtin.PKI-DH.private_key</name><value>file://$4/key.pem</value></property>
            <property><name>dds.sec.access.plugin</name><value>builtin.Access-Permissions</value></property>
            <property><name>dds.sec.access.builtin.Access-Permissions.permissions_ca</name><value>file://$3/permissions_ca.pem</value></property>
            <property><name>dds.sec.access.builtin.Access-Permissions.governance</name><value>file://$5</value></property>
            <property><name>dds.sec.access.builtin.Access-Permissions.permissions</name><value>file://$4/permissions.p7s</value></property>
            <property><name>dds.sec.crypto.plugin</name><value>builtin.AES-GCM-GMAC</value></property>
          </properties>
        </propertiesPolicy>"
  awk -v props="${props}" '
    /<participant / { in_participant = 1 }
    in_participant && /<\/rtps>/ && !done { print props; done = 1 }
    { print }
  ' "$1" | sed 's#<!-- \(LAN\|WAN\)#<!-- SECURE (DDS-Security, deploy/security/make-pki.sh). \1#' > "$2"
}

# make_pki CA_DIR ROLES...: the CAs, governance and the roles' identities, permissions and profiles.
make_domain() { # DIR CA_LABEL ROLES...
  local dir="$1" label="$2"
  shift 2
  mkdir -p "${dir}/ca"
  make_ca "${dir}/ca" identity_ca "canyon ${label} identity CA"
  make_ca "${dir}/ca" permissions_ca "canyon ${label} permissions CA"
  governance > "${dir}/governance.xml"
  sign "${dir}/ca" "${dir}/governance.xml" "${dir}/governance.p7s"
  local role rules
  for role in "$@"; do
    mkdir -p "${dir}/${role}"
    make_identity "${dir}/ca" "${dir}/${role}" "canyon ${role}"
    rules="rules_${role}"
    permissions "CN=canyon ${role},O=canyon,C=DE" "${role}" "${!rules}" > "${dir}/${role}/permissions.xml"
    sign "${dir}/ca" "${dir}/${role}/permissions.xml" "${dir}/${role}/permissions.p7s"
    local profile
    for profile in lan wan-initial-peers wan-discovery-server; do
      secure_profile "${dds_dir}/${profile}.xml" "${dir}/${role}/${profile}.xml" "${dir}/ca" "${dir}/${role}" \
        "${dir}/governance.p7s"
    done
  done
}

make_domain "${out}" test base rover monitor
make_domain "${out}/rogue" rogue intruder
# The intruder directory at the top level, next to the real roles.
rm -rf "${out}/intruder"
ln -s rogue/intruder "${out}/intruder"
chmod 600 "${out}"/ca/*.key "${out}"/*/key.pem "${out}"/rogue/ca/*.key 2> /dev/null || true
# Checks: every identity verifies against its CA, every signed document against its permissions CA.
for role in base rover monitor; do
  openssl verify -CAfile "${out}/ca/identity_ca.pem" "${out}/${role}/cert.pem" > /dev/null
  openssl smime -verify -in "${out}/${role}/permissions.p7s" -CAfile "${out}/ca/permissions_ca.pem" \
    -out /dev/null 2> /dev/null
done
openssl smime -verify -in "${out}/governance.p7s" -CAfile "${out}/ca/permissions_ca.pem" -out /dev/null 2> /dev/null
if openssl verify -CAfile "${out}/ca/identity_ca.pem" "${out}/intruder/cert.pem" > /dev/null 2>&1; then
  echo "make-pki: error: the intruder's certificate verifies against the real CA" >&2
  exit 1
fi
echo "make-pki: ${out}: CAs, governance, roles base rover monitor (and intruder of a rogue CA)"
