// Effect switches. A specialised variant defines KRS_<EFFECT> only for the scene's effects,
// and EFFECT_ON(bit) is constant true: the code of an absent effect is not in the source.
// The benchmark's "all effects" variant defines every KRS_<EFFECT> plus KRS_ALL_EFFECTS and
// switches each one by a bit of u_effects at run time, to measure what specialising saves.
#ifdef KRS_ALL_EFFECTS
uniform int u_effects;
#define EFFECT_ON(bit) ((u_effects & (bit)) != 0)
#else
#define EFFECT_ON(bit) true
#endif
