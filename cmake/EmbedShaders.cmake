# Embed GLSL files into the binary at build time (after bgfx's .sc -> .bin.h and
# magnum's resource compiler). Each file becomes an entry in a generated table
# that atonlab::gl::shader_source(name) looks up; editing a shader re-runs the
# generator. The shipped library's table is atonlab::gl::detail::embedded_shaders;
# atonlab_embed_shader_table(target TABLE files...) makes another table (the
# tests' own shaders), which its code hands to gl::add_shader_table.
function(atonlab_embed_shaders target)
  atonlab_embed_shader_table(${target} embedded_shaders ${ARGN})
endfunction()

function(atonlab_embed_shader_table target table)
  set(out_cpp ${CMAKE_CURRENT_BINARY_DIR}/${target}_${table}.cpp)
  set(abs_files)
  foreach(f IN LISTS ARGN)
    get_filename_component(abs ${f} ABSOLUTE)
    list(APPEND abs_files ${abs})
  endforeach()
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out_cpp} -DTABLE=${table} "-DFILES=${abs_files}"
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedShadersScript.cmake
    DEPENDS ${abs_files} ${PROJECT_SOURCE_DIR}/cmake/EmbedShadersScript.cmake
    COMMENT "Embedding shaders for ${target}"
    VERBATIM)
  target_sources(${target} PRIVATE ${out_cpp})
endfunction()
