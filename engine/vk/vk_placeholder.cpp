// vk: sources land here
