# EICAL_SANITIZE=address,undefined or thread applies to every target of this build tree.
if(EICAL_SANITIZE)
  add_compile_options(-fsanitize=${EICAL_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${EICAL_SANITIZE})
endif()
