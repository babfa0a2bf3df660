// A shared library without the effect entry points (gi_effect_abi_version,
// gi_register_effects): loadable, but not an effect module.
extern "C" __attribute__((visibility("default"))) int gi_test_not_an_effect() {
  return 42;
}
