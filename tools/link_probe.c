/* link_probe.c: an empty program linked to the same libraries as bumpbake
 * (and forced to load them: --no-as-needed), run once at build time under
 * the dynamic linker's LD_DEBUG=bindings by tools/link_order.sh, which
 * reads from it where the loader finds the symbols of OpenImageIO's ~260
 * libraries. */
int main(void) { return 0; }
