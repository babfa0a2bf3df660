#include "quantity.h"

#include <cmath>
#include <cstdio>

#include "gi/errors.h"

namespace gi::bench {

namespace ref = gi::reference;
using Kind = EstimatedQuantity::Kind;

namespace {

float checkedRadius(double r) {
  if (!std::isfinite(r) || !(r > 0.0))
    throw Error(ErrorKind::Usage, "", "an effect declared a non-positive or non-finite radius");
  return float(r);
}

std::string num(double v, const char* format) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

ReferenceSpec declaredSpec(const EstimatedQuantity& q) {
  ReferenceSpec s;
  switch (q.kind) {
    case Kind::AmbientOcclusion:
      s.quantity = ref::Quantity::AO;
      s.radius = checkedRadius(q.radius);
      break;
    case Kind::Obscurance:
      s.quantity = ref::Quantity::Obscurance;
      s.radius = checkedRadius(q.radius);
      s.membership = ref::parseMembership(q.membership);
      break;
    case Kind::Alchemy:
      s.quantity = ref::Quantity::Alchemy;
      s.radius = checkedRadius(q.radius);
      s.alchemy =
          ref::AlchemyParams{float(q.sigma), float(q.u), float(q.epsilon), float(q.contrast), 0.0f};
      break;
    case Kind::AlchemyDisk:
      s.quantity = ref::Quantity::AlchemyDisk;
      s.radius = checkedRadius(q.radius);
      s.alchemy = ref::AlchemyParams{float(q.sigma), float(q.u), float(q.epsilon),
                                     float(q.contrast), float(q.bias)};
      break;
    case Kind::DirectLight:
      s.quantity = ref::Quantity::Direct;
      break;
    case Kind::DirectIndirect:
      s.quantity = ref::Quantity::DirectIndirect;
      break;
  }
  return s;
}

ReferenceSpec targetSpec(GroundTruth truth, const EstimatedQuantity& declared, bool aoSplit) {
  ReferenceSpec s;
  switch (truth) {
    case GroundTruth::AmbientOcclusion:
      s.quantity = aoSplit ? ref::Quantity::AOSplit : ref::Quantity::AO;
      s.radius = checkedRadius(declared.radius);
      break;
    case GroundTruth::IndirectLight:
      s.quantity = ref::Quantity::DirectIndirect;
      break;
    case GroundTruth::DirectLight:
      s.quantity = ref::Quantity::Direct;
      break;
  }
  return s;
}

bool isAoLike(ref::Quantity q) {
  return q == ref::Quantity::AO || q == ref::Quantity::AOSplit || q == ref::Quantity::Obscurance ||
         q == ref::Quantity::Alchemy || q == ref::Quantity::AlchemyDisk;
}

std::string label(const ReferenceSpec& s) {
  // The ao-split reference's value is AO itself (the same estimate, see reference.h).
  std::string out =
      ref::quantityName(s.quantity == ref::Quantity::AOSplit ? ref::Quantity::AO : s.quantity);
  if (s.quantity == ref::Quantity::Obscurance)
    out += std::string(" ") + ref::membershipName(s.membership);
  if (isAoLike(s.quantity)) out += " r=" + num(s.radius, "%g");
  if (s.quantity == ref::Quantity::Alchemy || s.quantity == ref::Quantity::AlchemyDisk)
    out += " sigma=" + num(s.alchemy.sigma, "%g") + " u=" + num(s.alchemy.u, "%g") +
           " eps=" + num(s.alchemy.epsilon, "%g") + " k=" + num(s.alchemy.contrast, "%g");
  if (s.quantity == ref::Quantity::AlchemyDisk) out += " bias=" + num(s.alchemy.bias, "%g");
  return out;
}

std::string keyText(const ReferenceSpec& s) {
  std::string out = ref::quantityName(s.quantity);
  if (isAoLike(s.quantity)) out += "|r=" + num(s.radius, "%a");
  if (s.quantity == ref::Quantity::Obscurance)
    out += std::string("|mu=") + ref::membershipName(s.membership);
  if (s.quantity == ref::Quantity::Alchemy || s.quantity == ref::Quantity::AlchemyDisk)
    out += "|sigma=" + num(s.alchemy.sigma, "%a") + "|u=" + num(s.alchemy.u, "%a") +
           "|eps=" + num(s.alchemy.epsilon, "%a") + "|k=" + num(s.alchemy.contrast, "%a");
  if (s.quantity == ref::Quantity::AlchemyDisk) out += "|bias=" + num(s.alchemy.bias, "%a");
  return out;
}

void apply(const ReferenceSpec& s, ref::Settings& settings) {
  settings.quantity = s.quantity;
  settings.radius = isAoLike(s.quantity) ? s.radius : 0.5f;
  settings.membership = s.membership;
  settings.alchemy = s.alchemy;
}

}  // namespace gi::bench
