# Post-link step of proxgen_add_firmware (run with cmake -P): size report, optional soft-double
# check, stack report. Inputs (-D): ELF NAME OUT_DIR OBJ_DIR SIZE NM OBJDUMP PYTHON STACK_SCRIPT
# NO_SOFT_DOUBLE STACK_ROOTS (;-list).

# Size: Berkeley (text = flash code+rodata+vectors, data = initialised RAM, also stored in
# flash, bss = zeroed RAM) and per section (SysV).
execute_process(COMMAND "${SIZE}" --format=berkeley "${ELF}" OUTPUT_VARIABLE berkeley
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${SIZE} failed on ${ELF}")
endif()
execute_process(COMMAND "${SIZE}" -A -x "${ELF}" OUTPUT_VARIABLE sysv)
string(REGEX MATCH "\n *([0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)" m "${berkeley}")
set(text ${CMAKE_MATCH_1})
set(data ${CMAKE_MATCH_2})
set(bss ${CMAKE_MATCH_3})
math(EXPR flash "${text} + ${data}")
math(EXPR ram "${data} + ${bss}")
set(summary "${NAME}: flash ${flash} bytes (text ${text} + data ${data}), static RAM ${ram} bytes (data ${data} + bss ${bss}), stack not included")
file(WRITE "${OUT_DIR}/${NAME}.size.txt" "${summary}\n\n${berkeley}\n${sysv}")
message("${summary}")

if(NO_SOFT_DOUBLE)
  execute_process(COMMAND "${NM}" "${ELF}" OUTPUT_VARIABLE syms)
  string(REGEX MATCHALL "__aeabi_(dadd|dsub|dmul|ddiv|drsub|dcmp[a-z]+|d2f|f2d|i2d|ui2d|l2d|ul2d|d2iz|d2uiz|d2lz|d2ulz)" soft "${syms}")
  if(soft)
    list(REMOVE_DUPLICATES soft)
    file(REMOVE "${ELF}")
    message(FATAL_ERROR "${NAME}: NO_SOFT_DOUBLE, but double-precision soft-float helpers are "
                        "linked: ${soft}. Find the callers in ${OUT_DIR}/${NAME}.map "
                        "(compile with -Wdouble-promotion to spot implicit float->double).")
  endif()
endif()

if(PYTHON AND EXISTS "${STACK_SCRIPT}")
  set(roots --root Reset_Handler --root main)
  foreach(r IN LISTS STACK_ROOTS)
    list(APPEND roots --root "${r}")
  endforeach()
  execute_process(COMMAND "${PYTHON}" "${STACK_SCRIPT}" --elf "${ELF}" --objdump "${OBJDUMP}"
                          ${roots} --out "${OUT_DIR}/${NAME}.stack.txt" "${OBJ_DIR}"
                  OUTPUT_VARIABLE stack_out RESULT_VARIABLE rc)
  if(rc EQUAL 0)
    string(REGEX MATCH "worst stack from Reset_Handler: [0-9]+ bytes" line "${stack_out}")
    message("${NAME}: ${line} (details: ${NAME}.stack.txt)")
  else()
    message(WARNING "${NAME}: stack_report.py failed")
  endif()
endif()
