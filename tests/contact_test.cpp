// contact_test.cpp — (tests land with their stage)
