// neural: sources land here
